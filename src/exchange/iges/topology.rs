//! IGES trimmed faces and B-rep solids -> [`Topology`] over the curves and surfaces already
//! converted into [`Document::entities`].
//!
//! - 144 Trimmed Surface (IGES 5.3 section 4.34): a face on its surface (PTS) whose outer
//!   loop is PTO's 142 and whose holes are the PTI 142s; `N1 = 0` (the surface's own
//!   boundary) gives a face whose outer loop is that boundary, an edge over the iso-curve
//!   at each end of the domain (`Builder::natural_loop`). Each 142 Curve on a Parametric
//!   Surface (section 4.32) gives the loop's edges from its model-space curve C(t) (CPTR; the constituents of
//!   a 102 Composite Curve, section 4.4, are one edge each) and their pcurves from B(t)
//!   (BPTR) where the surface is a 128, whose parameter space is the NURBS surface's own;
//!   elsewhere (the analytic surfaces, whose IGES parameters are not the NURBS ones) the
//!   pcurve is computed ([`edge_pcurve`]: exact on planes and along isocurves, else by
//!   projection within the edge tolerance).
//!   The edges' ends become vertices shared across the file within the tolerance (the larger
//!   of the file's resolution, Global parameter 19, and 1e-7 of the model's size), and
//!   within the face's group: a 402 Group Associativity (forms 1, 7, 14, 15, IGES 5.3
//!   sections 4.81-4.89) that lists trimmed surfaces holds the faces of one shell, as Open
//!   CASCADE and nurbsx write them, and the faces of two groups share nothing (two solids
//!   that touch stay two solids). The faces no group lists form one group.
//! - 143 Bounded Surface (IGES 5.3 type 143): a face on its surface (SPTR) bounded by its
//!   141 Boundaries (BDPT, the first the outer one). Each 141 gives a loop of its model-space
//!   curves (CRVPT, a 102's constituents one edge each), reversed where SENSE = 2, with the
//!   parameter-space curves (PSCPT, TYPE = 1) as given pcurves on a 128 like a 142's.
//! - 186 Manifold Solid B-Rep Object with 514 Shell, 510 Face, 508 Loop, 504 Edge List and
//!   502 Vertex List (IGES 5.3 types 186, 502-514): the vertices and edges as the lists give
//!   them, shared by every loop that names them; loops with their orientation flags (OF),
//!   shells with their face orientations and closed/open form, solids with their voids.
//!
//! Every pointer followed must name an existing directory entry (an odd D sequence number)
//! of an allowed type, else a located `pointer.invalid` / `topology.wrong_entity` error;
//! every violation the [`crate::topology`] checks find is a located `topology.*` error; the
//! item is skipped and the rest of the file still reads.

use std::collections::{BTreeMap, HashMap};

use nurbsx_parsers::iges::DirectoryEntry;
use nurbsx_parsers::iges::records::{
    Boundary141, BoundedSurface143, BrepSolid186, CURVES, CompositeCurve102, CurveOnSurface142,
    EdgeList504, Face510, Group402, Loop508, SURFACES, Shell514, TrimmedSurface144, VertexList502,
};

use super::read::{Context, decoded, entity_location};
use crate::exchange::{
    Diagnostic, Document, Entity, Label, Location, Meta, Origin, Source, Topology,
};
use crate::nurbs::transform::apply;
use crate::nurbs::vector::dist;
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3};
use crate::topology::{
    Coedge, EdgeId, FaceId, Loop, ShellId, TopologyError, VertexId, edge_pcurve, moved_seams,
    seam_sides_by_continuity,
};

/// The builder's hash maps keyed by grid cells and ids: foldhash's `quality` hasher, a
/// fraction of SipHash's cost per lookup.
pub(super) type FoldMap<K, V> = HashMap<K, V, foldhash::quality::RandomState>;

/// Points (plus one) at which a file's parameter-space curve is checked against its edge.
const GIVEN_SAMPLES: usize = 32;

/// Relative tolerance of shared vertices (of the model's size).
const REL_TOL: f64 = 1e-7;

/// A B-rep edge whose curve ends further than the file tolerance from its 502 vertex gets
/// the gap as its tolerance (as the sending system's edge tolerance would be), up to this
/// multiple of the file tolerance; beyond it the edge is refused.
const MAX_GAP_FACTOR: f64 = 1e3;

/// The entity types that carry topology, and their names for the `topology.not_read`
/// warning.
pub(super) const TOPOLOGY_TYPES: [(i64, &str); 10] = [
    (144, "trimmed faces (144)"),
    (142, "face boundaries (142)"),
    (143, "bounded faces (143)"),
    (141, "face boundaries (141)"),
    (186, "solids (186)"),
    (514, "shells (514)"),
    (510, "faces (510)"),
    (508, "loops (508)"),
    (504, "edge lists (504)"),
    (502, "vertex lists (502)"),
];

/// Reads the file's faces, shells and solids into `doc.topology` (or, with
/// `geometry_only`, only says what it leaves out).
pub(super) fn read(cx: &Context<'_, '_>, doc: &mut Document, diags: &mut Vec<Diagnostic>) {
    let mut counts: BTreeMap<i64, usize> = BTreeMap::new();
    for e in cx.file.entries.iter().flatten() {
        if TOPOLOGY_TYPES.iter().any(|&(t, _)| t == e.entity_type)
            || matches!(e.entity_type, 308 | 408)
        {
            *counts.entry(e.entity_type).or_default() += 1;
        }
    }
    let count = |t: i64| counts.get(&t).copied().unwrap_or(0);
    // Subfigures without any topology (308/408 of curves and surfaces only) are not
    // applied: say so, visibly.
    let no_topology = TOPOLOGY_TYPES.iter().all(|&(t, _)| count(t) == 0);
    if count(408) > 0 && (no_topology || cx.options.geometry_only) {
        diags.push(Diagnostic::warning(
            "topology.not_read",
            format!(
                "{} x subfigure instances (408) are not applied to free curves and surfaces: the geometry of their 308 definitions is returned once, where the definition places it",
                count(408)
            ),
            Location::default(),
        )
        .not_carried());
    }
    if cx.options.geometry_only {
        let list: Vec<String> = TOPOLOGY_TYPES
            .iter()
            .filter(|&&(t, _)| count(t) > 0)
            .map(|&(t, name)| format!("{} {name}", count(t)))
            .collect();
        if !list.is_empty() {
            diags.push(Diagnostic::warning(
                "topology.not_read",
                format!(
                    "geometry only: the topology is not read ({}); the curves and surfaces are returned untrimmed",
                    list.join(", ")
                ),
                Location::default(),
            )
            .not_carried());
        }
        return;
    }
    if TOPOLOGY_TYPES.iter().all(|&(t, _)| count(t) == 0) {
        return;
    }
    let mut b = Builder::new(cx, &doc.entities);
    for entry in cx.file.entries.iter().flatten() {
        match entry.entity_type {
            144 if !b.face144(entry, diags) => b.trim_not_applied(entry, diags),
            143 if !b.face143(entry, diags) => b.trim_not_applied(entry, diags),
            186 => b.solid186(entry, diags),
            _ => {}
        }
    }
    // Shells no solid names (an open shell, a surface model) are read on their own.
    for entry in cx.file.entries.iter().flatten() {
        if entry.entity_type == 514 && !b.shells.keys().any(|&(de, _)| de == entry.pointer) {
            b.shell514(entry, true, diags);
        }
    }
    b.sew(diags);
    // Faces (510) that no shell names: a lone face, or a surface model written face by face
    // (IGES 5.3 section 4.146 does not require a 510 to sit in a 514). They share their 504
    // edge lists already, so they are read as they are, not sewn.
    for entry in cx.file.entries.iter().flatten() {
        if entry.entity_type == 510 && !b.faces.contains_key(&entry.pointer) {
            b.face510(entry, diags);
        }
    }
    b.report(diags);
    let (carried, moved_faces, natural) = (b.carried, b.moved_faces, b.natural);
    doc.topology = b.topology;
    doc.entities.extend(natural);
    doc.adopt_moved_surfaces(&moved_faces);
    super::subfigure::apply(cx, &mut doc.topology, diags);
    // What the model carries without naming it is not an entity of its own (a
    // parameter-space curve left to no coedge, or whose face was not read, stays one).
    // The conformance checks of `validate` keep every curve of the file (as the STEP
    // reader converts every PCURVE curve for them).
    if !carried.is_empty() && !cx.options.conformance {
        doc.entities.retain(|e| !carried.contains(&e.id));
    }
}

/// The 402 Group Associativities (forms 1, 7, 14 and 15, IGES 5.3 sections 4.81, 4.83,
/// 4.88, 4.89) that list trimmed faces (143, 144) directly: the faces of one shell, as Open
/// CASCADE writes them. Found once per file, before the entities are decoded. A group of
/// groups (Open CASCADE writes a compound so) lists no face directly and is none of them;
/// a group that does not decode is reported where the file's entities are checked.
#[derive(Debug, Default)]
pub(super) struct FaceGroups {
    /// The group of each face such a group lists, by DE pointer, numbered from 1 in file
    /// order (a face several groups list is in the first); the faces no group lists are
    /// group 0.
    pub of_face: FoldMap<usize, usize>,
    /// The DE pointers of those groups.
    pub groups: std::collections::BTreeSet<usize>,
}

impl FaceGroups {
    pub(super) fn of(file: &nurbsx_parsers::iges::IgesFile<'_>) -> Self {
        let mut out = FaceGroups::default();
        for entry in file.entries.iter().flatten() {
            if entry.entity_type != 402 || ![1, 7, 14, 15].contains(&entry.form) {
                continue;
            }
            let Ok(group) = file.decode::<Group402>(entry).record else {
                continue;
            };
            let next = out.groups.len() + 1;
            let mut any = false;
            for member in group.members.iter().filter_map(|&m| file.entry(m)) {
                if matches!(member.entity_type, 143 | 144) {
                    out.of_face.entry(member.pointer).or_insert(next);
                    any = true;
                }
            }
            if any {
                out.groups.insert(entry.pointer);
            }
        }
        out
    }
}

/// Builds the topology of one file.
struct Builder<'c, 'f, 'a> {
    cx: &'c Context<'f, 'a>,
    /// DE pointer -> index in the document's entities.
    by_de: BTreeMap<usize, usize>,
    entities: &'c [Entity],
    topology: Topology,
    /// The file's tolerance (module documentation).
    tol: f64,
    /// Vertices of the 142 curves' ends by group and grid cell of size `2 tol`.
    grid: FoldMap<(usize, [i64; 3]), Vec<VertexId>>,
    /// The group of the face being built ([`FaceGroups::of_face`]).
    group: usize,
    /// The group of each face built.
    face_group: FoldMap<FaceId, usize>,
    list_vertices: BTreeMap<(usize, i64), Option<VertexId>>,
    list_edges: BTreeMap<(usize, i64), Option<EdgeId>>,
    vertex_lists: BTreeMap<usize, Option<VertexList502>>,
    edge_lists: BTreeMap<usize, Option<EdgeList504>>,
    faces: BTreeMap<usize, Option<FaceId>>,
    shells: BTreeMap<(usize, bool), Option<ShellId>>,
    /// Edges whose tolerance was widened to their vertex gap.
    widened: usize,
    /// Vertex uses of 508 loops (TYPE = 1), implied by their neighbouring edges.
    vertex_uses: usize,
    /// 142/141 boundary pieces whose model-space curve is a point (degenerate sides).
    degenerate_pieces: usize,
    /// Coedges built, and those left without a pcurve.
    coedges: usize,
    no_pcurve: usize,
    /// The file's parameter-space curve (B(t) piece, 141 PSCPT, 508 CURV) given for each
    /// coedge of the face being built, in the order of its loops and coedges.
    given: Vec<Vec<Label>>,
    /// The curves of the face being built's boundary pieces collapsed to a point (model
    /// space, and the parameter-space piece given with it): the loop's vertex carries them.
    collapsed: Vec<Label>,
    /// The entities the model carries without naming them, which are not entities of
    /// their own in the document: the parameter-space curves of coedges of faces in the
    /// model (each such coedge has its pcurve: the given curve on a 128, else computed; as
    /// a STEP file's PCURVE curves are not entities), the boundary curves of edges that
    /// sewing merged into others (the same edge within the tolerance), and the boundary
    /// pieces of those faces collapsed to a point.
    carried: std::collections::HashSet<Label>,
    /// The faces added with their surface's seam moved ([`Builder::with_moved_seam`]).
    moved_faces: Vec<FaceId>,
    /// The curves of the domain boundaries given to faces bounded by their surface's domain
    /// ([`Builder::natural_loop`]), entities the document lists.
    natural: Vec<Entity>,
    /// How many faces got their domain's boundary as a loop.
    natural_faces: usize,
}

/// A curve of the document with its DE pointer.
struct Piece<'c> {
    de: usize,
    entity: &'c Entity,
    curve: &'c NurbsCurve,
}

impl<'c, 'f, 'a> Builder<'c, 'f, 'a> {
    fn new(cx: &'c Context<'f, 'a>, entities: &'c [Entity]) -> Self {
        let mut by_de = BTreeMap::new();
        let mut size: f64 = 1.0;
        for (i, e) in entities.iter().enumerate() {
            if let Some(de) = e.id.strip_prefix('D').and_then(|d| d.parse::<usize>().ok()) {
                by_de.insert(de, i);
            }
            let points: &[Point3] = match &e.geometry {
                Geometry::Curve(c) if c.dimension() == 3 => c.control_points(),
                Geometry::Surface(s) => s.control_points().as_slice(),
                Geometry::Curve(_) => &[],
            };
            size = points
                .iter()
                .flatten()
                .fold(size, |m, x| if x.is_finite() { m.max(x.abs()) } else { m });
        }
        // The user's sewing tolerance is their word on how precise the file is: boundary
        // curve ends are joined into loops within it too, not only faces into shells (a gap
        // inside a loop that sewing would close must not first refuse the face).
        let tol = cx
            .options
            .sew_tolerance
            .unwrap_or_else(|| (REL_TOL * size).max(cx.file.global.resolution.unwrap_or(0.0)));
        Builder {
            cx,
            by_de,
            entities,
            topology: Topology::default(),
            tol,
            grid: FoldMap::default(),
            group: 0,
            face_group: FoldMap::default(),
            list_vertices: BTreeMap::new(),
            list_edges: BTreeMap::new(),
            vertex_lists: BTreeMap::new(),
            edge_lists: BTreeMap::new(),
            faces: BTreeMap::new(),
            shells: BTreeMap::new(),
            widened: 0,
            vertex_uses: 0,
            degenerate_pieces: 0,
            coedges: 0,
            no_pcurve: 0,
            given: Vec::new(),
            collapsed: Vec::new(),
            carried: std::collections::HashSet::new(),
            moved_faces: Vec::new(),
            natural: Vec::new(),
            natural_faces: 0,
        }
    }

    /// Trimmed faces (144) that no shell holds, each with its own boundary curves, are sewn
    /// (shared vertices and edges, consistent orientation; [`crate::topology::Model::sew`])
    /// into shells, and solids where they close up; edges that stay open are reported.
    fn sew(&mut self, diags: &mut Vec<Diagnostic>) {
        let m = &self.topology.model;
        let mut in_shell = vec![false; m.faces.len()];
        for s in &m.shells {
            for &(f, _) in &s.faces {
                if let Some(x) = in_shell.get_mut(f.0) {
                    *x = true;
                }
            }
        }
        let loose: Vec<FaceId> = (0..m.faces.len())
            .filter(|&i| !in_shell[i])
            .map(FaceId)
            .collect();
        if loose.is_empty() {
            return;
        }
        // The loose faces by group (module documentation), groups in file order.
        let mut by_group: BTreeMap<usize, Vec<FaceId>> = BTreeMap::new();
        for &f in &loose {
            let g = self.face_group.get(&f).copied().unwrap_or(0);
            by_group.entry(g).or_default().push(f);
        }
        let groups: Vec<Vec<FaceId>> = by_group.into_values().collect();
        let tol = self.tol;
        let before = self.topology.model.clone();
        let sewing = match self.topology.model.sew(&groups, tol) {
            // A lone face is sewn only to itself: where its boundary runs twice along one
            // edge (a sphere's or a closed extrusion's seam, written once per side in a 144
            // file, or the one seam edge of a face bounded by its closed surface's domain),
            // else it stays a loose face.
            Ok(s) if loose.len() == 1 && s.merged_edges == 0 && s.solids.is_empty() => {
                self.topology.model = before;
                return;
            }
            Ok(s) => s,
            Err(e) => {
                self.topology.model = before;
                diags.push(Diagnostic::warning(
                    "topology.not_sewn",
                    format!(
                        "the {} trimmed faces are kept loose: sewing them within {tol:e} failed ({e})",
                        loose.len()
                    ),
                    Location::default(),
                ));
                return;
            }
        };
        let o = &mut self.topology.origins;
        let keep = |list: &mut Vec<Origin>, map: &[Option<crate::topology::EdgeId>]| {
            let old = std::mem::take(list);
            *list = old
                .into_iter()
                .zip(map)
                .filter(|(_, m)| m.is_some())
                .map(|(x, _)| x)
                .collect();
        };
        // The boundary curves of the edges merged into others are those edges' curves
        // (within the tolerance), not free curves: carried, unless a kept edge names them.
        let merged: Vec<Label> = o
            .edges
            .iter()
            .zip(&sewing.edge_map)
            .filter(|(_, m)| m.is_none())
            .filter_map(|(x, _)| x.entity.clone())
            .collect();
        keep(&mut o.edges, &sewing.edge_map);
        let named = o.entity_ids();
        let merged: Vec<Label> = merged
            .into_iter()
            .filter(|id| !named.contains(id.as_str()))
            .collect();
        self.carried.extend(merged);
        let o = &mut self.topology.origins;
        let old = std::mem::take(&mut o.vertices);
        o.vertices = old
            .into_iter()
            .zip(&sewing.vertex_map)
            .filter(|(_, m)| m.is_some())
            .map(|(x, _)| x)
            .collect();
        let made = |what: &str, k: usize| Origin {
            id: compact_str::format_compact!("sewn {what} {}", k + 1),
            source: Source {
                entity: "144 (sewn)".into(),
                line: None,
            },
            name: None,
            entity: None,
        };
        for k in 0..sewing.shells.len() {
            o.shells.push(made("shell", k));
        }
        for k in 0..sewing.solids.len() {
            o.solids.push(made("solid", k));
        }
        diags.push(Diagnostic::info(
            "topology.sewn",
            format!(
                "{} trimmed faces sewn within {tol:e}: {} edges shared, {} shell(s), {} closed into solid(s)",
                loose.len(),
                sewing.merged_edges,
                sewing.shells.len(),
                sewing.solids.len()
            ),
            Location::default(),
        ));
        if !sewing.open_edges.is_empty() {
            let ids: Vec<String> = sewing
                .open_edges
                .iter()
                .take(8)
                .filter_map(|e| o.edges.get(e.0).map(|x| x.id.to_string()))
                .collect();
            // Open edges in pairs that nearly coincide: faces that almost close, worth a
            // warning; open edges without a partner are the border of a surface model
            // (IGES 5.3 section 4.147, form 2 open shell, allows a set of faces that bounds no solid): a note.
            let name = |e: EdgeId| {
                o.edges
                    .get(e.0)
                    .map_or_else(String::new, |x| x.id.to_string())
            };
            let (severity, message): (fn(_, _, _) -> Diagnostic, String) = if let Some(widest) =
                sewing.gaps.iter().map(|g| g.2).reduce(f64::max)
            {
                let (a, b, _) = sewing.gaps[0];
                (
                    Diagnostic::warning,
                    format!(
                        "{} edges of the sewn faces are used by one face only; {} pair(s) of them nearly coincide (first: {} and {}), gaps up to {widest:e}: the faces almost close, and --sew-tolerance {:e} would sew them",
                        sewing.open_edges.len(),
                        sewing.gaps.len(),
                        name(a),
                        name(b),
                        widest * 1.01
                    ),
                )
            } else if !sewing.gaps_complete {
                (
                    Diagnostic::warning,
                    format!(
                        "{} edges of the sewn faces are used by one face only, so their shell stays open (first: {}); too many overlap to tell a near miss from a border, and a larger --sew-tolerance may close it",
                        sewing.open_edges.len(),
                        ids.join(", ")
                    ),
                )
            } else {
                (
                    Diagnostic::info,
                    format!(
                        "the sewn faces form an open surface model: {} edges on its border are used by one face only (first: {}), none with another open edge near it",
                        sewing.open_edges.len(),
                        ids.join(", ")
                    ),
                )
            };
            diags.push(severity(
                "topology.open_edges",
                message,
                ids.first()
                    .map(|id| Location::at_entity(id.clone()))
                    .unwrap_or_default(),
            ));
        }
        if sewing.lost_pcurves > 0 {
            diags.push(
                Diagnostic::warning(
                    "pcurve.not_computed",
                    format!(
                        "{} parameter-space curves could not be carried to their sewn edges",
                        sewing.lost_pcurves
                    ),
                    Location::default(),
                )
                .not_carried(),
            );
        }
    }

    /// The summary diagnostics of the whole file.
    fn report(&self, diags: &mut Vec<Diagnostic>) {
        if self.widened > 0 {
            diags.push(Diagnostic::info(
                "topology.edge_tolerance",
                format!(
                    "{} B-rep edges end further than the file tolerance {:e} from their vertices; each keeps the gap as its tolerance (at most {MAX_GAP_FACTOR} x the file tolerance)",
                    self.widened, self.tol
                ),
                Location::default(),
            ));
        }
        if self.natural_faces > 0 {
            diags.push(Diagnostic::info(
                "topology.domain_boundary",
                format!(
                    "{} faces bounded by their surface's own domain (144 N1 = 0) get that boundary as their outer loop: the iso-curves at the domain's ends (exact), one seam edge where the surface closes, none where a side collapses to a pole; they are listed as curves D<face>:u0 .. :v1",
                    self.natural_faces
                ),
                Location::default(),
            ));
        }
        if self.vertex_uses > 0 {
            diags.push(Diagnostic::info(
                "topology.vertex_use",
                format!(
                    "{} vertex uses in 508 loops (TYPE = 1, degenerate sides at poles and apexes) are the vertex the neighbouring edges share; no degenerate edge is made for them",
                    self.vertex_uses
                ),
                Location::default(),
            ));
        }
        if self.degenerate_pieces > 0 {
            diags.push(Diagnostic::info(
                "topology.degenerate_side",
                format!(
                    "{} boundary pieces of 142/141 curves are a single point in model space (degenerate sides at poles and apexes, as Open CASCADE writes them); no degenerate edge is made for them, the neighbouring edges share their vertex",
                    self.degenerate_pieces
                ),
                Location::default(),
            ));
        }
        if self.no_pcurve > 0 {
            // The faces keep their exact 3-D boundaries; only this derived form is missing,
            // but the faces' area, volume and mesh need it: a warning, as for STEP.
            diags.push(Diagnostic::warning(
                "pcurve.not_computed",
                format!(
                    "{} of {} coedges have no parameter-space curve (neither given exactly nor found by projection within the edge tolerance {:e})",
                    self.no_pcurve, self.coedges, self.tol
                ),
                Location::default(),
            )
            .not_carried());
        }
    }

    /// The entry `p` names from `from`'s field `field`, if it exists and has one of the
    /// `allowed` types; else a located error.
    fn target(
        &self,
        from: &DirectoryEntry,
        field: &str,
        p: i64,
        allowed: &[i64],
        diags: &mut Vec<Diagnostic>,
    ) -> Option<&'f DirectoryEntry> {
        let Some(e) = self.cx.file.entry(p) else {
            diags.push(Diagnostic::error(
                "pointer.invalid",
                format!(
                    "{} {field} = {p} names no directory entry (an odd D sequence number of this file); skipped",
                    from.entity_type
                ),
                entity_location(from),
            ));
            return None;
        };
        if !allowed.contains(&e.entity_type) {
            diags.push(Diagnostic::error(
                "topology.wrong_entity",
                format!(
                    "{} {field} = D{} is a {} entity, not one of {allowed:?}; skipped",
                    from.entity_type, e.pointer, e.entity_type
                ),
                entity_location(from),
            ));
            return None;
        }
        Some(e)
    }

    /// The converted geometry of entry `e`, or a located error.
    fn entity(
        &self,
        from: &DirectoryEntry,
        e: &DirectoryEntry,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<&'c Entity> {
        let found = self.by_de.get(&e.pointer).map(|&i| &self.entities[i]);
        if found.is_none() {
            diags.push(Diagnostic::error(
                "topology.geometry_missing",
                format!(
                    "{} names D{} ({}), which was not converted (see its own diagnostic); skipped",
                    from.entity_type, e.pointer, e.entity_type
                ),
                entity_location(from),
            ));
        }
        found
    }

    /// The surface `p` names, converted.
    fn surface(
        &self,
        from: &DirectoryEntry,
        field: &str,
        p: i64,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(&'c Entity, &'c NurbsSurface)> {
        let e = self.target(from, field, p, SURFACES, diags)?;
        let ent = self.entity(from, e, diags)?;
        match &ent.geometry {
            Geometry::Surface(s) => Some((ent, s)),
            Geometry::Curve(_) => None,
        }
    }

    /// The curves `p` names: one, or the constituents of a 102 in order.
    fn curves(
        &self,
        from: &DirectoryEntry,
        field: &str,
        p: i64,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Vec<Piece<'c>>> {
        let e = self.target(from, field, p, CURVES, diags)?;
        let members = if e.entity_type == 102 && !self.by_de.contains_key(&e.pointer) {
            let rec = decoded(self.cx.file.decode::<CompositeCurve102>(e), diags)?;
            let mut list = Vec::with_capacity(rec.members.len());
            for m in rec.members {
                list.push(self.target(e, "DE", m, CURVES, diags)?);
            }
            list
        } else {
            vec![e]
        };
        let mut out = Vec::with_capacity(members.len());
        for m in members {
            let ent = self.entity(from, m, diags)?;
            let Geometry::Curve(c) = &ent.geometry else {
                return None;
            };
            out.push(Piece {
                de: m.pointer,
                entity: ent,
                curve: c,
            });
        }
        if out.is_empty() {
            diags.push(Diagnostic::error(
                "topology.loop_open",
                format!("{} {field} = {p} holds no curve; skipped", from.entity_type),
                entity_location(from),
            ));
            return None;
        }
        Some(out)
    }

    /// The vertex at `p`: an existing one within the tolerance, else a new one.
    fn shared_vertex(&mut self, p: Point3, origin: &Origin) -> Result<VertexId, TopologyError> {
        let cell = 2.0 * self.tol;
        let key = |x: f64| (x / cell).floor() as i64;
        let k = [key(p[0]), key(p[1]), key(p[2])];
        let model = &self.topology.model;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let c = [k[0] + dx, k[1] + dy, k[2] + dz];
                    if let Some(list) = self.grid.get(&(self.group, c))
                        && let Some(&v) = list
                            .iter()
                            .find(|v| dist(model.vertices[v.0].point, p) <= self.tol)
                    {
                        return Ok(v);
                    }
                }
            }
        }
        let v = self.topology.model.add_vertex(p, self.tol)?;
        self.topology.origins.vertices.push(origin.clone());
        self.grid.entry((self.group, k)).or_default().push(v);
        Ok(v)
    }

    /// The part of a curve an edge uses: the declared parameter range when it lies in the
    /// knot domain (IGES 126 `V(0), V(1)`), else the domain.
    fn range(piece: &Piece<'_>) -> (f64, f64) {
        let d = piece.curve.domain();
        piece
            .entity
            .meta
            .parameter_range
            .as_deref()
            .map(|r| r.u)
            .filter(|r| r.0 >= d.0 && r.1 <= d.1 && r.0 < r.1)
            .unwrap_or(d)
    }

    fn origin(entry: &DirectoryEntry, id: Label, entity: Option<&Entity>) -> Origin {
        Origin {
            id,
            source: Source {
                entity: super::entity_type_name(entry.entity_type),
                line: Some(entry.line),
            },
            name: (!entry.label.is_empty()).then(|| entry.label.clone()),
            entity: entity.map(|e| e.id.clone()),
        }
    }

    /// An edge over a 142 boundary piece, its ends shared vertices.
    fn boundary_edge(
        &mut self,
        from: &DirectoryEntry,
        piece: &Piece<'c>,
    ) -> Result<EdgeId, TopologyError> {
        let range = Self::range(piece);
        let origin = Origin {
            id: compact_str::format_compact!("D{}", piece.de),
            source: piece.entity.source.clone(),
            name: piece.entity.meta.name.clone(),
            entity: Some(piece.entity.id.clone()),
        };
        let vertex_origin = Self::origin(
            from,
            compact_str::format_compact!("D{}", from.pointer),
            None,
        );
        let start = self.shared_vertex(piece.curve.point_at_unchecked(range.0), &vertex_origin)?;
        let end = self.shared_vertex(piece.curve.point_at_unchecked(range.1), &vertex_origin)?;
        let e = self
            .topology
            .model
            .add_edge(piece.curve.clone(), range, start, end, self.tol)?;
        self.topology.origins.edges.push(origin);
        Ok(e)
    }

    /// The pcurve of edge `e` on `surface`: the file's parameter-space curve where the
    /// surface is a 128 (whose (u, v) are the NURBS surface's; reparameterised affinely to
    /// the edge's range, in whichever direction matches the edge), else [`edge_pcurve`]
    /// (exact on planes and along isocurves, else by projection).
    fn pcurve(
        &mut self,
        surface: (&Entity, &NurbsSurface),
        given: Option<&NurbsCurve>,
        e: EdgeId,
    ) -> Option<NurbsCurve> {
        self.coedges += 1;
        let edge = &self.topology.model.edges[e.0];
        let (a, b) = edge.range;
        let tol = edge.tolerance;
        let (ent, s) = surface;
        let ((u0, u1), (v0, v1)) = s.domain();
        let on = |c: &NurbsCurve, t: f64| {
            let [u, v, _] = c.point_at_unchecked(t);
            s.point_at_unchecked(u.clamp(u0, u1), v.clamp(v0, v1))
        };
        let found = given
            .filter(|p| ent.source.entity == "128" && p.dimension() == 2)
            .and_then(|p| {
                let candidates = [
                    p.reparameterize(a, b).ok(),
                    p.reverse().and_then(|r| r.reparameterize(a, b)).ok(),
                ];
                // Checked at `GIVEN_SAMPLES + 1` points (the face check samples as densely):
                // a given curve off its edge between the ends falls back to edge_pcurve.
                candidates.into_iter().flatten().find(|c| {
                    (0..=GIVEN_SAMPLES).all(|k| {
                        let t = (a + (b - a) * k as f64 / GIVEN_SAMPLES as f64).min(b);
                        dist(on(c, t), edge.curve.point_at_unchecked(t)) <= tol
                    })
                })
            })
            .or_else(|| {
                edge_pcurve(s, None, &edge.curve, (a, b), tol)
                    .ok()
                    .filter(|p| p.deviation <= tol)
                    .map(|p| p.curve)
            });
        if found.is_none() {
            self.no_pcurve += 1;
        }
        found
    }

    /// Coedges without a pcurve whose edge crosses the surface's seam but not the face's:
    /// the first surface with its seam moved to a vertex of the face ([`moved_seams`]) on
    /// which every coedge gets a pcurve ([`edge_pcurve`]) replaces the surface (the same
    /// surface, exactly), and `loops` get those pcurves.
    fn with_moved_seam(
        &mut self,
        surface: &NurbsSurface,
        loops: &mut [Loop],
    ) -> Option<NurbsSurface> {
        let missing = loops
            .iter()
            .flat_map(|l| &l.coedges)
            .filter(|c| c.pcurve.is_none())
            .count();
        if missing == 0 {
            return None;
        }
        let m = &self.topology.model;
        for candidate in moved_seams(surface, m, loops, self.tol) {
            let mut trial = loops.to_vec();
            let found = trial.iter_mut().flat_map(|l| &mut l.coedges).all(|c| {
                let e = &m.edges[c.edge.0];
                c.pcurve = edge_pcurve(&candidate, None, &e.curve, e.range, e.tolerance)
                    .ok()
                    .filter(|p| p.deviation <= e.tolerance)
                    .map(|p| p.curve);
                c.pcurve.is_some()
            });
            if found {
                loops.clone_from_slice(&trial);
                self.no_pcurve -= missing;
                return Some(candidate);
            }
        }
        None
    }

    /// Adds a face; a coedge whose pcurve the check refuses loses it and the face is
    /// checked again, any other violation is a located error.
    /// `loop_entries[i]` is the 142 or 508 loop `i` came from (a loop's violation is
    /// located there).
    fn add_face(
        &mut self,
        entry: &DirectoryEntry,
        surface: (&Entity, &NurbsSurface),
        mut loops: Vec<Loop>,
        loop_entries: &[&DirectoryEntry],
        trimmed: bool,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<FaceId> {
        let total: usize = loops.iter().map(|l| l.coedges.len()).sum();
        let moved = self.with_moved_seam(surface.1, &mut loops);
        let nurbs = moved.as_ref().unwrap_or(surface.1);
        // Pcurves on a seam take the side where the loop continues: both coedges of a seam
        // edge, and (144) each boundary piece along the seam.
        let mut uses: HashMap<EdgeId, usize> = HashMap::new();
        for c in loops.iter().flat_map(|l| &l.coedges) {
            *uses.entry(c.edge).or_default() += 1;
        }
        for l in &mut loops {
            // IGES faces are added with the surface's sense (`add_face(.., true)` below).
            seam_sides_by_continuity(nurbs, &mut l.coedges, true, |e| {
                trimmed || uses.get(&e) == Some(&2)
            });
        }
        for _ in 0..=total {
            match self
                .topology
                .model
                .add_face(nurbs.clone(), loops.clone(), true)
            {
                Ok(f) => {
                    self.face_group.insert(f, self.group);
                    self.topology.origins.faces.push(Self::origin(
                        entry,
                        compact_str::format_compact!("D{}", entry.pointer),
                        Some(surface.0),
                    ));
                    let coedges = loops.iter().flat_map(|l| &l.coedges);
                    for (c, given) in coedges.zip(std::mem::take(&mut self.given)) {
                        if c.pcurve.is_some() {
                            self.carried.extend(given);
                        }
                    }
                    self.carried.extend(self.collapsed.drain(..));
                    if moved.is_some() {
                        self.moved_faces.push(f);
                    }
                    return Some(f);
                }
                Err(TopologyError::PcurveDeviates { index, coedge, .. }) => {
                    if let Some(c) = loops.get_mut(index).and_then(|l| l.coedges.get_mut(coedge)) {
                        c.pcurve = None;
                        self.no_pcurve += 1;
                    }
                }
                Err(e) => {
                    let at = match &e {
                        TopologyError::LoopOpen { index, .. } => loop_entries.get(*index),
                        _ => None,
                    };
                    let mut d = topology_error(at.copied().unwrap_or(entry), &e);
                    d.message = format!("{} (face D{})", d.message, entry.pointer);
                    diags.push(d);
                    return None;
                }
            }
        }
        None
    }

    /// The `trim_ignored` note on the surface of a 144 or 143 whose face could not be read.
    fn trim_not_applied(&self, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) {
        let surface = match entry.entity_type {
            144 => self
                .cx
                .file
                .decode::<TrimmedSurface144>(entry)
                .record
                .map(|r| r.surface),
            _ => self
                .cx
                .file
                .decode::<BoundedSurface143>(entry)
                .record
                .map(|r| r.surface),
        };
        let Ok(surface) = surface else {
            return;
        };
        if let Some(s) = self.cx.file.entry(surface)
            && self.by_de.contains_key(&s.pointer)
        {
            diags.push(Diagnostic::info(
                "trim_ignored",
                format!(
                    "used by D{} ({}), whose face is not read (see its diagnostic); the untrimmed surface is returned",
                    entry.pointer, entry.entity_type
                ),
                entity_location(s),
            )
            .not_carried());
        }
    }

    /// Forgets what the last face built noted of its boundary ([`Builder::given`],
    /// [`Builder::collapsed`]): a face read in part leaves them behind.
    fn start_face(&mut self, entry: &DirectoryEntry) {
        self.given.clear();
        self.collapsed.clear();
        self.group = (self.cx.face_groups.of_face)
            .get(&entry.pointer)
            .copied()
            .unwrap_or(0);
    }

    /// A 143 Bounded Surface as a face; whether it was built.
    fn face143(&mut self, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) -> bool {
        self.start_face(entry);
        let Some(rec) = decoded(self.cx.file.decode::<BoundedSurface143>(entry), diags) else {
            return false;
        };
        let Some(surface) = self.surface(entry, "SPTR", rec.surface, diags) else {
            return false;
        };
        let mut loops = Vec::with_capacity(rec.boundaries.len());
        let mut at = Vec::with_capacity(rec.boundaries.len());
        for (k, &p) in rec.boundaries.iter().enumerate() {
            let given = rec.kind == 1;
            let Some((l, e)) = self.loop141(entry, p, k == 0, given, rec.surface, surface, diags)
            else {
                return false;
            };
            loops.push(l);
            at.push(e);
        }
        self.add_face(entry, surface, loops, &at, true, diags)
            .is_some()
    }

    /// A 141 Boundary as a loop: its model-space curves in order, each reversed where its
    /// SENSE is 2, one coedge per curve piece; the parameter-space curves (when the 143 and
    /// the 141 both say TYPE = 1) as given pcurves when they are as many as the pieces.
    #[allow(clippy::too_many_arguments)]
    fn loop141(
        &mut self,
        face: &DirectoryEntry,
        p: i64,
        outer: bool,
        given: bool,
        sptr: i64,
        surface: (&'c Entity, &'c NurbsSurface),
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(Loop, &'f DirectoryEntry)> {
        let e = self.target(face, "BDPT", p, &[141], diags)?;
        let rec = decoded(self.cx.file.decode::<Boundary141>(e), diags)?;
        if rec.surface != sptr {
            diags.push(Diagnostic::nonconforming(
                "topology.boundary_surface",
                format!(
                    "SPTR = {} is not the surface of the bounded surface D{} ({sptr}); the boundary is read on D{}'s surface",
                    rec.surface, face.pointer, face.pointer
                ),
                entity_location(e),
            ));
        }
        let mut coedges = Vec::new();
        for c in &rec.curves {
            let mut model = self.curves(e, "CRVPT", c.curve, diags)?;
            let mut params: Vec<Piece<'c>> = Vec::new();
            if given && rec.kind == 1 {
                for &q in &c.parameter_curves {
                    params.extend(self.curves(e, "PSCPT", q, diags)?);
                }
            }
            let forward = c.sense != 2;
            if !forward {
                model.reverse();
                params.reverse();
            }
            let params = (params.len() == model.len()).then_some(params);
            let pieces = self.boundary_coedges(e, &model, params.as_deref(), forward, surface);
            coedges.extend(
                pieces
                    .map_err(|err| diags.push(topology_error(e, &err)))
                    .ok()?,
            );
        }
        if coedges.is_empty() {
            diags.push(Diagnostic::error(
                "topology.loop_open",
                format!(
                    "141 D{} holds no curve; the face D{} is skipped",
                    e.pointer, face.pointer
                ),
                entity_location(e),
            ));
            return None;
        }
        Some((Loop { coedges, outer }, e))
    }

    /// The outer loop of a face bounded by its surface's own domain (a 144 with `N1 = 0`,
    /// IGES 5.3 section 4.34, as Open CASCADE writes a face that is its whole surface): the
    /// four iso-curves at the ends of the domain (exact, NURBS Book section 5.4's iso-curves
    /// of the net), counter-clockwise in (u, v), each an edge between vertices shared with
    /// the rest of the face's group, with the line along the side as its pcurve. A side that
    /// collapses to a point (a pole) gives no edge; on a surface closed across a pair of
    /// sides both use one seam edge, each with its own pcurve. The curves are listed as
    /// entities of their own (`D<face>:u0`, `:u1`, `:v0`, `:v1`, source `144 (domain
    /// boundary)`), so that a writer writes them and a reader finds them again. `None`
    /// (the face stays bounded by the domain) when a side cannot be made.
    fn natural_loop(
        &mut self,
        entry: &DirectoryEntry,
        surface: (&'c Entity, &'c NurbsSurface),
    ) -> Option<Loop> {
        let s = surface.1;
        let ((u0, u1), (v0, v1)) = s.domain();
        let tol = self.tol;
        let closed = [s.is_closed_u(tol), s.is_closed_v(tol)];
        // (label, iso-curve, fixed direction 0 = u, its value, the pcurve's other
        // coordinate, coedge forward): bottom, right, top, left.
        let sides = [
            ("v0", s.iso_v(v0).ok()?, 1, v0, true),
            ("u1", s.iso_u(u1).ok()?, 0, u1, true),
            ("v1", s.iso_v(v1).ok()?, 1, v1, false),
            ("u0", s.iso_u(u0).ok()?, 0, u0, false),
        ];
        // First everything that can fail, so that a side that cannot be made leaves the
        // model as it was: per side that is not a pole, its curve, pcurve and end points.
        let mut planned = Vec::with_capacity(4);
        for (label, iso, d, at, forward) in sides {
            let poles = iso.control_points();
            let first = *poles.first()?;
            if poles.iter().all(|p| dist(*p, first) <= tol) {
                continue; // a pole: no edge
            }
            // The pcurve: the side's line in (u, v), parameterised as the edge's curve.
            let (a, b) = iso.domain();
            let ends = if d == 0 {
                [[at, a, 0.0], [at, b, 0.0]]
            } else {
                [[a, at, 0.0], [b, at, 0.0]]
            };
            let pcurve =
                NurbsCurve::with_dimension(1, vec![a, a, b, b], ends.to_vec(), None, 2).ok()?;
            let points = [iso.point_at(a).ok()?, iso.point_at(b).ok()?];
            if !points.iter().flatten().all(|x| x.is_finite()) {
                return None;
            }
            planned.push((label, iso, d, forward, pcurve, points));
        }
        if planned.is_empty() {
            return None;
        }
        let vertex_origin = Self::origin(
            entry,
            compact_str::format_compact!("D{}", entry.pointer),
            None,
        );
        let mut coedges = Vec::with_capacity(planned.len());
        // The seam edges made so far: (fixed direction, edge).
        let mut seams: Vec<(usize, EdgeId)> = Vec::new();
        for (label, iso, d, forward, pcurve, points) in planned {
            // On a closed surface the second side of the pair reuses the first one's edge
            // (the curves are the same within the tolerance; the first is kept).
            let edge = match seams.iter().find(|(k, _)| *k == d).map(|&(_, e)| e) {
                Some(e) if closed[d] => e,
                _ => {
                    let start = self.shared_vertex(points[0], &vertex_origin).ok()?;
                    let end = self.shared_vertex(points[1], &vertex_origin).ok()?;
                    let id = compact_str::format_compact!("D{}:{label}", entry.pointer);
                    let range = iso.domain();
                    let e = self
                        .topology
                        .model
                        .add_edge(iso.clone(), range, start, end, tol)
                        .ok()?;
                    let mut meta = Meta::default();
                    meta.used_by
                        .push(compact_str::format_compact!("D{}", entry.pointer));
                    let source = Source {
                        entity: "144 (domain boundary)".into(),
                        line: Some(entry.line),
                    };
                    self.natural.push(Entity {
                        id: id.clone(),
                        geometry: Geometry::Curve(iso),
                        source: source.clone(),
                        meta,
                    });
                    self.topology.origins.edges.push(Origin {
                        id: id.clone(),
                        source,
                        name: None,
                        entity: Some(id),
                    });
                    seams.push((d, e));
                    e
                }
            };
            self.given.push(Vec::new());
            coedges.push(Coedge {
                edge,
                forward,
                pcurve: Some(pcurve),
                pcurve_deviation: None,
            });
        }
        self.natural_faces += 1;
        Some(Loop {
            coedges,
            outer: true,
        })
    }

    /// A 144 Trimmed Surface as a face; whether it was built.
    fn face144(&mut self, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) -> bool {
        self.start_face(entry);
        let Some(rec) = decoded(self.cx.file.decode::<TrimmedSurface144>(entry), diags) else {
            return false;
        };
        let Some(surface) = self.surface(entry, "PTS", rec.surface, diags) else {
            return false;
        };
        let mut loops = Vec::with_capacity(1 + rec.inner.len());
        let mut at = Vec::with_capacity(1 + rec.inner.len());
        if rec.outer_given != 0 && rec.outer == 0 {
            diags.push(Diagnostic::warning(
                "topology.outer_missing",
                "N1 = 1 but PTO = 0: the face is read bounded by its surface's own domain"
                    .to_owned(),
                entity_location(entry),
            ));
        }
        let outer = (rec.outer_given != 0 && rec.outer != 0).then_some(("PTO", rec.outer, true));
        if outer.is_none() {
            // Bounded by the surface's own domain: that boundary, as edges.
            if let Some(l) = self.natural_loop(entry, surface) {
                loops.push(l);
                at.push(entry);
            }
        }
        let inner = rec.inner.iter().map(|&b| ("PTI", b, false));
        for (field, p, is_outer) in outer.into_iter().chain(inner) {
            let Some((l, e)) = self.loop142(entry, field, p, is_outer, surface, diags) else {
                return false;
            };
            loops.push(l);
            at.push(e);
        }
        self.add_face(entry, surface, loops, &at, true, diags)
            .is_some()
    }

    /// A 142 Curve on a Parametric Surface as a loop: one coedge per model-space curve
    /// piece, in order.
    fn loop142(
        &mut self,
        face: &DirectoryEntry,
        field: &str,
        p: i64,
        outer: bool,
        surface: (&'c Entity, &'c NurbsSurface),
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(Loop, &'f DirectoryEntry)> {
        let e = self.target(face, field, p, &[142], diags)?;
        let rec = decoded(self.cx.file.decode::<CurveOnSurface142>(e), diags)?;
        if rec.model_curve == 0 {
            diags.push(Diagnostic::warning(
                "topology.no_model_curve",
                format!(
                    "CPTR = 0 (PREF = {}): a boundary given only in parameter space is not read; the face D{} is skipped",
                    rec.preferred, face.pointer
                ),
                entity_location(e),
            ));
            return None;
        }
        let model = self.curves(e, "CPTR", rec.model_curve, diags)?;
        let params = if rec.parameter_curve == 0 {
            None
        } else {
            self.curves(e, "BPTR", rec.parameter_curve, diags)
        }
        .filter(|p| p.len() == model.len());
        let coedges = self
            .boundary_coedges(e, &model, params.as_deref(), true, surface)
            .map_err(|err| diags.push(topology_error(e, &err)))
            .ok()?;
        Some((Loop { coedges, outer }, e))
    }

    /// One coedge per model-space curve piece of a 142 or 141 (`from`), `forward` or
    /// reversed, with the matching parameter-space piece as its given pcurve.
    fn boundary_coedges(
        &mut self,
        from: &DirectoryEntry,
        model: &[Piece<'c>],
        params: Option<&[Piece<'c>]>,
        forward: bool,
        surface: (&'c Entity, &'c NurbsSurface),
    ) -> Result<Vec<Coedge>, TopologyError> {
        let mut coedges = Vec::with_capacity(model.len());
        for (i, piece) in model.iter().enumerate() {
            // A side collapsed to a point (a pole, an apex) bounds nothing in model space:
            // the edges before and after it meet at its point (as for 508 vertex uses).
            let poles = piece.curve.control_points();
            let point = poles.iter().all(|p| {
                poles
                    .first()
                    .is_some_and(|q| (0..3).all(|k| (p[k] - q[k]).abs() <= self.tol))
            });
            if point && model.len() > 1 {
                self.degenerate_pieces += 1;
                self.collapsed.push(piece.entity.id.clone());
                self.collapsed
                    .extend(params.and_then(|ps| ps.get(i)).map(|q| q.entity.id.clone()));
                continue;
            }
            let edge = self.boundary_edge(from, piece)?;
            let given = params.and_then(|ps| ps.get(i));
            self.given
                .push(given.map(|q| q.entity.id.clone()).into_iter().collect());
            let pcurve = self.pcurve(surface, given.map(|q| q.curve), edge);
            coedges.push(Coedge {
                edge,
                forward,
                pcurve,
                pcurve_deviation: None,
            });
        }
        Ok(coedges)
    }

    /// A 186 Manifold Solid B-Rep Object as a solid.
    fn solid186(&mut self, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) {
        let Some(rec) = decoded(self.cx.file.decode::<BrepSolid186>(entry), diags) else {
            return;
        };
        let Some(outer) = self
            .target(entry, "SHELL", rec.shell.0, &[514], diags)
            .and_then(|s| self.shell514(s, rec.shell.1 != 0, diags))
        else {
            return;
        };
        let mut voids = Vec::with_capacity(rec.voids.len());
        for &(v, of) in &rec.voids {
            let Some(s) = self
                .target(entry, "VOID", v, &[514], diags)
                .and_then(|s| self.shell514(s, of != 0, diags))
            else {
                return;
            };
            voids.push(s);
        }
        match self.topology.model.add_solid(outer, voids) {
            Ok(_) => self.topology.origins.solids.push(Self::origin(
                entry,
                compact_str::format_compact!("D{}", entry.pointer),
                None,
            )),
            Err(e) => diags.push(topology_error(entry, &e)),
        }
    }

    /// A 514 Shell, its faces turned over when `same` is false (a 186's SOF / VOF = 0).
    /// Form 1 declares it closed; when it is not, it is kept as an open shell with an
    /// error (its solid is then refused).
    fn shell514(
        &mut self,
        entry: &'f DirectoryEntry,
        same: bool,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<ShellId> {
        if let Some(s) = self.shells.get(&(entry.pointer, same)) {
            return *s;
        }
        self.shells.insert((entry.pointer, same), None);
        let rec = decoded(self.cx.file.decode::<Shell514>(entry), diags)?;
        let mut faces = Vec::with_capacity(rec.faces.len());
        for &(f, of) in &rec.faces {
            if let Some(face) = self
                .target(entry, "FACE", f, &[510], diags)
                .and_then(|fe| self.face510(fe, diags))
            {
                faces.push((face, (of != 0) == same));
            }
        }
        let shell = match self.topology.model.add_shell(faces.clone(), rec.form == 1) {
            Ok(s) => Some(s),
            Err(e) => {
                diags.push(Diagnostic::error(
                    "topology.shell_open",
                    format!("514 entity: {e}; kept as an open shell (a solid on it is refused)"),
                    entity_location(entry),
                ));
                self.topology.model.add_shell(faces, false).ok()
            }
        };
        if shell.is_some() {
            self.topology.origins.shells.push(Self::origin(
                entry,
                compact_str::format_compact!("D{}", entry.pointer),
                None,
            ));
        }
        self.shells.insert((entry.pointer, same), shell);
        shell
    }

    /// A 510 Face (once, however many shells name it).
    fn face510(&mut self, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) -> Option<FaceId> {
        if let Some(f) = self.faces.get(&entry.pointer) {
            return *f;
        }
        self.faces.insert(entry.pointer, None);
        self.start_face(entry);
        let rec = decoded(self.cx.file.decode::<Face510>(entry), diags)?;
        let surface = self.surface(entry, "SURF", rec.surface, diags)?;
        let mut loops = Vec::with_capacity(rec.loops.len());
        let mut at = Vec::with_capacity(rec.loops.len());
        let mut vertex_loops = Vec::new();
        for (k, &l) in rec.loops.iter().enumerate() {
            let outer = k == 0 && rec.outer_first != 0;
            let lp = self.target(entry, "LOOP", l, &[508], diags)?;
            match self.loop508(lp, outer, surface, diags)? {
                Ok(l) => {
                    loops.push(l);
                    at.push(lp);
                }
                Err(v) => vertex_loops.push(v),
            }
        }
        let f = self.add_face(entry, surface, loops, &at, false, diags);
        if let Some(face) = f.and_then(|f| self.topology.model.faces.get_mut(f.0)) {
            face.vertex_loops = vertex_loops;
        }
        self.faces.insert(entry.pointer, f);
        f
    }

    /// A 508 Loop: its edge uses with their orientation flags and pcurves; `Err` with the
    /// vertex for a loop of one vertex use alone (a vertex loop: a sphere's pole, a cone's
    /// apex, ISO 10303-42 vertex_loop).
    fn loop508(
        &mut self,
        entry: &DirectoryEntry,
        outer: bool,
        surface: (&'c Entity, &'c NurbsSurface),
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Result<Loop, VertexId>> {
        let rec = decoded(self.cx.file.decode::<Loop508>(entry), diags)?;
        if let [use_] = rec.edges.as_slice()
            && use_.kind == 1
        {
            return self
                .list_vertex(entry, "EDGE", (use_.edge, use_.index), diags)
                .map(Err);
        }
        let mut coedges = Vec::with_capacity(rec.edges.len());
        for use_ in &rec.edges {
            if use_.kind != 0 {
                // A vertex use (TYPE = 1: a degenerate side such as a sphere's pole or a
                // cone's apex) joins the edges before and after it, which already share
                // that vertex: the chain of edges is the loop.
                self.vertex_uses += 1;
                continue;
            }
            let list = self.target(entry, "EDGE", use_.edge, &[504], diags)?;
            let edge = self.list_edge(list, use_.index, diags)?;
            let given = match use_.parameter_curves.as_slice() {
                [(_, c)] if *c != 0 => self
                    .curves(entry, "CURV", *c, diags)
                    .filter(|p| p.len() == 1)
                    .and_then(|mut p| p.pop()),
                _ => None,
            };
            // Every curve of the use's parameter-space list (one, or the pieces of one
            // curve; a list of several is not taken as the given pcurve) is the coedge's.
            self.given.push(
                use_.parameter_curves
                    .iter()
                    .filter_map(|&(_, c)| usize::try_from(c).ok())
                    .filter_map(|c| self.by_de.get(&c))
                    .filter_map(|&i| self.entities.get(i))
                    .map(|e| e.id.clone())
                    .collect(),
            );
            let pcurve = self.pcurve(surface, given.map(|q| q.curve), edge);
            coedges.push(Coedge {
                edge,
                forward: use_.orientation != 0,
                pcurve,
                pcurve_deviation: None,
            });
        }
        Some(Ok(Loop { coedges, outer }))
    }

    /// Edge `index` (from 1) of a 504 Edge List, built once.
    fn list_edge(
        &mut self,
        list: &DirectoryEntry,
        index: i64,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<EdgeId> {
        if let Some(e) = self.list_edges.get(&(list.pointer, index)) {
            return *e;
        }
        self.list_edges.insert((list.pointer, index), None);
        if !self.edge_lists.contains_key(&list.pointer) {
            let rec = decoded(self.cx.file.decode::<EdgeList504>(list), diags);
            self.edge_lists.insert(list.pointer, rec);
        }
        let edge = self
            .edge_lists
            .get(&list.pointer)
            .and_then(Option::as_ref)
            .and_then(|l| nth(&l.edges, index));
        let Some(edge) = edge else {
            diags.push(Diagnostic::error(
                "pointer.invalid",
                format!("edge index NDX = {index} is not an edge of this list; skipped"),
                entity_location(list),
            ));
            return None;
        };
        let pieces = self.curves(list, "CURV", edge.curve, diags)?;
        let [piece] = pieces.as_slice() else {
            diags.push(Diagnostic::error(
                "topology.edge_composite",
                format!(
                    "edge {index}: its curve D{} is a 102 of {} pieces, not one curve; skipped",
                    edge.curve,
                    pieces.len()
                ),
                entity_location(list),
            ));
            return None;
        };
        let start = self.list_vertex(list, "SVP", edge.start, diags)?;
        let end = self.list_vertex(list, "TVP", edge.end, diags)?;
        let range = Self::range(piece);
        let m = &self.topology.model;
        let gap = dist(
            piece.curve.point_at_unchecked(range.0),
            m.vertices[start.0].point,
        )
        .max(dist(
            piece.curve.point_at_unchecked(range.1),
            m.vertices[end.0].point,
        ));
        let mut tol = self.tol;
        if gap > tol && gap <= MAX_GAP_FACTOR * tol {
            tol = gap * (1.0 + 1e-9);
            self.widened += 1;
        }
        let e = match self
            .topology
            .model
            .add_edge(piece.curve.clone(), range, start, end, tol)
        {
            Ok(e) => e,
            Err(err) => {
                diags.push(topology_error(list, &err));
                return None;
            }
        };
        self.topology.origins.edges.push(Origin {
            id: compact_str::format_compact!("D{}:{index}", list.pointer),
            source: piece.entity.source.clone(),
            name: piece.entity.meta.name.clone(),
            entity: Some(piece.entity.id.clone()),
        });
        self.list_edges.insert((list.pointer, index), Some(e));
        Some(e)
    }

    /// Vertex `index` (from 1) of the 502 Vertex List `p`, built once: its 124 chain and
    /// the unit factor applied as to every other entity.
    fn list_vertex(
        &mut self,
        from: &DirectoryEntry,
        field: &str,
        (p, index): (i64, i64),
        diags: &mut Vec<Diagnostic>,
    ) -> Option<VertexId> {
        let list = self.target(from, field, p, &[502], diags)?;
        if let Some(v) = self.list_vertices.get(&(list.pointer, index)) {
            return *v;
        }
        self.list_vertices.insert((list.pointer, index), None);
        if !self.vertex_lists.contains_key(&list.pointer) {
            let rec =
                decoded(self.cx.file.decode::<VertexList502>(list), diags).and_then(|mut rec| {
                    let chain = self.cx.transforms(list, &mut Meta::default(), diags)?;
                    for q in &mut rec.points {
                        if let Some(m) = &chain {
                            *q = apply(m, *q);
                        }
                        if let Some(f) = self.cx.factor {
                            *q = [q[0] * f, q[1] * f, q[2] * f];
                        }
                    }
                    Some(rec)
                });
            self.vertex_lists.insert(list.pointer, rec);
        }
        let point = self
            .vertex_lists
            .get(&list.pointer)
            .and_then(Option::as_ref)
            .and_then(|l| nth(&l.points, index));
        let Some(point) = point else {
            diags.push(Diagnostic::error(
                "pointer.invalid",
                format!(
                    "{field} names vertex {index} of D{}, which has no such vertex; skipped",
                    list.pointer
                ),
                entity_location(from),
            ));
            return None;
        };
        let v = match self.topology.model.add_vertex(point, self.tol) {
            Ok(v) => v,
            Err(e) => {
                diags.push(topology_error(list, &e));
                return None;
            }
        };
        self.topology.origins.vertices.push(Self::origin(
            list,
            compact_str::format_compact!("D{}:{index}", list.pointer),
            None,
        ));
        self.list_vertices.insert((list.pointer, index), Some(v));
        Some(v)
    }
}

/// Item `index` of a list that IGES indexes from 1 (502 vertices, 504 edges).
fn nth<T: Copy>(list: &[T], index: i64) -> Option<T> {
    let i = usize::try_from(index).ok()?.checked_sub(1)?;
    list.get(i).copied()
}

/// A refused piece of topology as a located error with a stable code.
fn topology_error(entry: &DirectoryEntry, e: &TopologyError) -> Diagnostic {
    let code = match e {
        TopologyError::LoopOpen { .. } => "topology.loop_open",
        TopologyError::PcurveDeviates { .. } => "topology.pcurve_deviates",
        TopologyError::EdgeMissesVertex { .. } => "topology.edge_vertex",
        TopologyError::EdgeRange { .. } => "topology.edge_range",
        TopologyError::ShellNotClosed { .. } => "topology.shell_open",
        TopologyError::SolidShellOpen { .. } => "topology.solid_shell_open",
        TopologyError::BadVertex { .. } => "topology.vertex",
        _ => "topology.invalid",
    };
    Diagnostic::error(
        code,
        format!("{} entity: {e}; skipped", entry.entity_type),
        entity_location(entry),
    )
}
