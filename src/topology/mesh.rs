//! # Triangle meshes of trimmed faces, watertight across shared edges
//!
//! [`Model::mesh`] tessellates the faces of a part within a chord tolerance:
//! - **Edges first, once each.** Every edge's 3-D curve, restricted to the edge's range, is
//!   cut into chords by the osculating-circle rule of [`NurbsCurve::tessellate_within`]
//!   (seed 004); the ends are the edge's vertices, and a straight edge or seam is one
//!   chord (the boundary needs no more: the faces' triangles along it are refined inside
//!   the face, against the surface). A degenerate edge (a pole of a sphere or
//!   the apex of a cone: its curve is one point within the edge's tolerance) is that one
//!   point. Every face bounded by an edge uses exactly these points, so two faces sharing an
//!   edge share its vertices bit for bit and the mesh of a closed shell has no crack.
//! - **The boundary in the parameter plane.** Each coedge's points are carried into the
//!   face surface's `(u, v)` by its pcurve at the same parameters (ISO 10303-42 clause 4.4.2,
//!   surface_curve: the pcurve shares the edge curve's parameter), or, without a pcurve, by
//!   inverting the 3-D points onto the surface ([`invert_surface`], NURBS Book section 6.1).
//!   A seam edge is used twice by its face with two pcurves (at `u0` and `u1`), so the
//!   boundary is a proper polygon in the plane; a degenerate edge becomes a segment of the
//!   plane (the pole's parameter line) whose points are all the same 3-D point.
//! - **Interior points** come from the surface's own adaptive grid
//!   ([`NurbsSurface::tessellate_within`], refined where the surface is not flat within the
//!   tolerance), kept only strictly inside the trimmed region (even-odd rule over all loops:
//!   the outer loop minus the holes) and away from the boundary by half the local grid step.
//! - **Constrained Delaunay triangulation** of boundary and interior points in the plane,
//!   with the boundary segments as constraints; triangles whose centroid lies outside the
//!   region are dropped. The plane is scaled by the surface's mean speeds `|S_u|` and
//!   `|S_v|` first, so that lengths in it are close to lengths on the surface and the
//!   Delaunay triangles are not slivers on long thin patches.
//! - **Refinement:** each triangle is compared with the surface at its centroid and at the
//!   midpoints of its inner edges (the surface point at the same parameters against the
//!   flat triangle's); the worst point of a triangle farther than the tolerance is inserted,
//!   round after round, until every triangle passes or [`MAX_ROUNDS`] rounds have run.
//! - **Orientation:** the triangles run counter-clockwise seen from the face normal, so a
//!   closed shell with outward faces gives a positive signed volume. The face normal is the
//!   side the loops run counter-clockwise about (ISO 10303-42 face_bound), which in a
//!   consistent file is `S_u x S_v` when `same_sense` holds and its reverse otherwise;
//!   faces where the two disagree (IGES 144 faces have no `same_sense`) are listed in
//!   [`PartMesh::against_same_sense`]. A face without loops follows `same_sense`.
//!
//! A face without loops is bounded by its surface's domain: its mesh is the surface's grid.
//! A face that cannot be meshed (its loops do not close in the parameter plane, as a loop
//! that winds around a closed surface without a seam edge; boundary segments that cross;
//! points that cannot be placed on the surface) is left out and named in
//! [`PartMesh::skipped`] with the reason; nothing on the input makes the mesher panic.
//! The work is bounded by a [`Budget`]: the vertices of all faces and edges together, and
//! a stop test polled every [`STOP_POLL`] steps.

use std::collections::{HashMap, HashSet};

use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::{EdgeId, Face, FaceId, Model};
use crate::nurbs::project::invert_surface;
use crate::nurbs::tessellate::{Budget, Mesh, Polyline, STOP_POLL, TessellationError};
use crate::nurbs::vector::{cross, dist, norm};
use crate::nurbs::{NurbsSurface, Point3};

/// Rounds of refinement of a face's triangulation at most.
pub const MAX_ROUNDS: usize = 64;

/// Points a degenerate edge's parameter segment is cut into.
const POLE_PIECES: usize = 16;

/// Samples per direction for the surface's mean speeds.
const SPEED_SAMPLES: usize = 5;

/// Why a face was left out of the mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FaceMeshError {
    /// A loop whose pcurves do not meet in the parameter plane.
    #[error(
        "loop {index}: its boundary leaves a gap of {gap:e} in the parameter plane after \
         coedge {coedge} (a loop around a closed surface without a seam edge?)"
    )]
    OpenInParameters {
        /// Loop index in the face.
        index: usize,
        /// The coedge after which the gap is.
        coedge: usize,
        /// The gap, in parameter units.
        gap: f64,
    },
    /// A point of an edge could not be placed in the parameter plane.
    #[error("loop {index}, coedge {coedge}: an edge point has no finite (u, v) on the surface")]
    NoParameters {
        /// Loop index in the face.
        index: usize,
        /// Coedge index in the loop.
        coedge: usize,
    },
    /// Boundary segments cross each other in the parameter plane.
    #[error("loop {index}: the boundary crosses itself or another loop in the parameter plane")]
    BoundaryCrosses {
        /// Loop index in the face.
        index: usize,
    },
    /// An edge of the face could not be tessellated.
    #[error("edge {edge}: {reason}")]
    Edge {
        /// Edge index in the model.
        edge: usize,
        /// Why.
        reason: String,
    },
    /// The surface could not be tessellated or gives non-finite points.
    #[error("surface: {0}")]
    Surface(String),
}

/// The mesh of a part.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PartMesh {
    /// One mesh per face of the model, index-aligned with `Model::faces` (`None`: not
    /// asked for or skipped). Vertices shared by faces are bitwise the same points.
    pub faces: Vec<Option<Mesh>>,
    /// One polyline per edge, index-aligned with `Model::edges`, with the edge curve's
    /// parameters (`None`: not asked for or not tessellated).
    pub edges: Vec<Option<Polyline>>,
    /// The faces left out, with the reason.
    pub skipped: Vec<(FaceId, FaceMeshError)>,
    /// Triangles that still exceed the tolerance after [`MAX_ROUNDS`] rounds (0 when every
    /// triangle passed).
    pub unrefined: usize,
    /// Faces whose loops run against their `same_sense` (meshed as their loops say).
    pub against_same_sense: Vec<FaceId>,
}

/// A point of a loop: its `(u, v)` (scaled once in the ring), where it comes from, and
/// its 3-D position.
type BoundaryPoint = ([f64; 2], Key, Point3);

/// Where a boundary point comes from: a vertex, or the `k`-th inner point of an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Vertex(usize),
    Edge(usize, usize),
}

/// A point of the triangulation: its scaled parameters and its vertex in the face mesh.
#[derive(Debug, Clone, Copy)]
struct Node {
    at: Point2<f64>,
    id: u32,
}

impl HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.at
    }
}

/// Counts units of work and polls the stop test every [`STOP_POLL`] of them.
struct Poll<'a> {
    budget: &'a Budget<'a>,
    work: usize,
}

impl Poll<'_> {
    fn tick(&mut self) -> Result<(), TessellationError> {
        self.work += 1;
        if self.work % STOP_POLL == 0 && (self.budget.stop)() {
            return Err(TessellationError::Stopped);
        }
        Ok(())
    }
}

impl Model {
    /// Meshes the faces `which` (all faces with `None`) and the edges they use (all edges
    /// with `None`) within the chord `tolerance` (see the module). Errors only for a bad
    /// tolerance, the budget's vertex limit or its stop test; a face that cannot be meshed
    /// is named in [`PartMesh::skipped`].
    pub fn mesh(
        &self,
        which: Option<&[FaceId]>,
        tolerance: f64,
        budget: &Budget<'_>,
    ) -> Result<PartMesh, TessellationError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(TessellationError::Geometry(
                crate::nurbs::GeometryError::InvalidArgument(format!(
                    "tessellation: tolerance {tolerance} must be finite and > 0"
                )),
            ));
        }
        let faces: Vec<usize> = match which {
            Some(list) => list
                .iter()
                .map(|f| f.0)
                .filter(|&f| f < self.faces.len())
                .collect(),
            None => (0..self.faces.len()).collect(),
        };
        let mut wanted_edges = vec![which.is_none(); self.edges.len()];
        for &f in &faces {
            for l in &self.faces[f].loops {
                for c in &l.coedges {
                    if let Some(w) = wanted_edges.get_mut(c.edge.0) {
                        *w = true;
                    }
                }
            }
        }
        let mut out = PartMesh {
            faces: vec![None; self.faces.len()],
            edges: vec![None; self.edges.len()],
            skipped: Vec::new(),
            unrefined: 0,
            against_same_sense: Vec::new(),
        };
        let mut used = 0usize;
        let mut edge_errors: HashMap<usize, String> = HashMap::new();
        for (i, &wanted) in wanted_edges.iter().enumerate() {
            if !wanted {
                continue;
            }
            let left = Budget {
                max_points: budget.max_points.saturating_sub(used),
                stop: budget.stop,
            };
            match self.edge_polyline(EdgeId(i), tolerance, &left) {
                Ok(p) => {
                    used += p.points.len();
                    out.edges[i] = Some(p);
                }
                Err(TessellationError::Geometry(g)) => {
                    edge_errors.insert(i, g.to_string());
                }
                Err(other) => return Err(other),
            }
        }
        let mut poll = Poll { budget, work: 0 };
        for f in faces {
            let face = &self.faces[f];
            if let Some((edge, reason)) = face
                .loops
                .iter()
                .flat_map(|l| &l.coedges)
                .find_map(|c| edge_errors.get(&c.edge.0).map(|r| (c.edge.0, r.clone())))
            {
                out.skipped
                    .push((FaceId(f), FaceMeshError::Edge { edge, reason }));
                continue;
            }
            let left = budget.max_points.saturating_sub(used);
            match self.face_mesh(face, &out.edges, tolerance, left, &mut poll) {
                Ok((mesh, unrefined, along)) => {
                    used += mesh.vertices.len();
                    out.unrefined += unrefined;
                    if along != face.same_sense {
                        out.against_same_sense.push(FaceId(f));
                    }
                    out.faces[f] = Some(mesh);
                }
                Err(Skip::Face(reason)) => out.skipped.push((FaceId(f), reason)),
                Err(Skip::Stop(e)) => return Err(e),
            }
        }
        Ok(out)
    }

    /// The chords of an edge's curve over its range within `tolerance`, ends at the
    /// vertices, with the curve's parameters; one point (repeated) for a degenerate edge.
    pub fn edge_polyline(
        &self,
        edge: EdgeId,
        tolerance: f64,
        budget: &Budget<'_>,
    ) -> Result<Polyline, TessellationError> {
        let e = self.edges.get(edge.0).ok_or_else(|| {
            TessellationError::Geometry(crate::nurbs::GeometryError::InvalidArgument(format!(
                "edge {} does not exist",
                edge.0
            )))
        })?;
        let piece = e.curve.piece(e.range.0, e.range.1)?;
        let mut line = piece.tessellate_within(tolerance, budget)?;
        let start = self.vertices.get(e.start.0).map(|v| v.point);
        let end = self.vertices.get(e.end.0).map(|v| v.point);
        let first = line.points.first().copied().unwrap_or([0.0; 3]);
        let span = line
            .points
            .iter()
            .fold(0.0f64, |m, p| m.max(dist(*p, first)));
        if e.start == e.end && span <= e.tolerance {
            let p = start.unwrap_or(first);
            let (a, b) = e.range;
            line.params = (0..=POLE_PIECES)
                .map(|k| a + (b - a) * k as f64 / POLE_PIECES as f64)
                .collect();
            line.points = vec![p; POLE_PIECES + 1];
            return Ok(line);
        }
        if let (Some(s), Some(p)) = (start, line.points.first_mut()) {
            *p = s;
        }
        if let (Some(s), Some(p)) = (end, line.points.last_mut()) {
            *p = s;
        }
        Ok(line)
    }

    /// One face's mesh, with the number of triangles left above the tolerance and whether
    /// the face normal is `S_u x S_v`.
    fn face_mesh(
        &self,
        face: &Face,
        edges: &[Option<Polyline>],
        tolerance: f64,
        max_points: usize,
        poll: &mut Poll<'_>,
    ) -> Result<(Mesh, usize, bool), Skip> {
        let s = &face.surface;
        let stop = poll.budget.stop;
        let grid = s
            .tessellate_within(tolerance, &Budget { max_points, stop })
            .map_err(|e| match e {
                TessellationError::Geometry(g) => Skip::Face(FaceMeshError::Surface(g.to_string())),
                other => Skip::Stop(other),
            })?;
        // A face whose every edge is a seam (used twice by the face, as a torus cut along
        // its two seams) covers its whole closed surface: meshed like a face without loops.
        let mut uses: HashMap<usize, usize> = HashMap::new();
        for c in face.loops.iter().flat_map(|l| &l.coedges) {
            *uses.entry(c.edge.0).or_default() += 1;
        }
        let all_seams = !uses.is_empty() && uses.values().all(|&n| n == 2);
        if face.loops.is_empty() || all_seams {
            let mut mesh = grid;
            if !face.same_sense {
                for t in &mut mesh.triangles {
                    t.swap(1, 2);
                }
            }
            mesh.normals = mesh
                .params
                .iter()
                .map(|&[u, v]| normal(s, u, v, face.same_sense))
                .collect();
            return Ok((mesh, 0, face.same_sense));
        }
        let plane = Plane::of(s);
        let mut b = Builder::default();
        // The loops in the scaled plane: points with their keys.
        let mut polygons: Vec<Vec<BoundaryPoint>> = Vec::new();
        let ((u0, u1), (v0, v1)) = s.domain();
        let closure = 1e-3 * (u1 - u0).hypot(v1 - v0);
        let periods = plane.periods;
        for (index, l) in face.loops.iter().enumerate() {
            // Each coedge's points in walking order, both ends included.
            let mut pieces: Vec<(usize, Vec<BoundaryPoint>)> = Vec::new();
            // Start at a coedge with a pcurve, so that points inverted onto the surface
            // follow on from known parameters.
            let first = l
                .coedges
                .iter()
                .position(|c| c.pcurve.is_some())
                .unwrap_or(0);
            let n_co = l.coedges.len();
            // A seam edge whose two uses carry the same pcurve (the file gave one): each
            // use goes to the side of the seam its neighbours are on.
            let one_pcurve_seam: Vec<bool> = l
                .coedges
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    l.coedges.iter().enumerate().any(|(j, d)| {
                        j != k && d.edge == c.edge && same_pcurve(c, d, self, closure)
                    })
                })
                .collect();
            let mut guess: Option<(f64, f64)> = None;
            for k in (0..n_co).map(|j| (j + first) % n_co) {
                let c = &l.coedges[k];
                let e = self.edges.get(c.edge.0).ok_or_else(|| {
                    Skip::Face(FaceMeshError::Edge {
                        edge: c.edge.0,
                        reason: "missing".into(),
                    })
                })?;
                let line = edges
                    .get(c.edge.0)
                    .and_then(Option::as_ref)
                    .ok_or_else(|| {
                        Skip::Face(FaceMeshError::Edge {
                            edge: c.edge.0,
                            reason: "not tessellated".into(),
                        })
                    })?;
                let n = line.params.len();
                let order: Vec<usize> = if c.forward {
                    (0..n).collect()
                } else {
                    (0..n).rev().collect()
                };
                let mut piece = Vec::with_capacity(n);
                let mut offset: Option<[f64; 2]> = None;
                for &i in &order {
                    poll.tick().map_err(Skip::Stop)?;
                    let t = line.params[i];
                    let p = line.points[i];
                    let uv = match &c.pcurve {
                        Some(pc) => {
                            let (pa, pb) = pc.domain();
                            let q = pc.point_at_unchecked(t.clamp(pa, pb));
                            [q[0], q[1]]
                        }
                        None => match invert_surface(s, p, guess) {
                            Some(inv) => [inv.u, inv.v],
                            None => [f64::NAN; 2],
                        },
                    };
                    // A seam point has two parameters: a point inverted onto the seam
                    // goes to the side the boundary is on; a one-pcurve seam use is shifted
                    // whole by the period that joins it to the coedge before.
                    let uv = if c.pcurve.is_none() {
                        unwrap(uv, guess, periods)
                    } else if one_pcurve_seam[k] {
                        let d = *offset.get_or_insert_with(|| {
                            let w = unwrap(uv, guess, periods);
                            [w[0] - uv[0], w[1] - uv[1]]
                        });
                        [uv[0] + d[0], uv[1] + d[1]]
                    } else {
                        uv
                    };
                    if !(uv[0].is_finite() && uv[1].is_finite()) {
                        return Err(Skip::Face(FaceMeshError::NoParameters { index, coedge: k }));
                    }
                    guess = Some((uv[0], uv[1]));
                    let key = if i == 0 {
                        Key::Vertex(e.start.0)
                    } else if i + 1 == n {
                        Key::Vertex(e.end.0)
                    } else if e.start == e.end && line.points.iter().all(|q| *q == p) {
                        Key::Vertex(e.start.0)
                    } else {
                        Key::Edge(c.edge.0, i)
                    };
                    piece.push((uv, key, p));
                }
                pieces.push((k, piece));
            }
            // The ring: each coedge without its last point (the next one's first), and
            // where two coedges meet at a pole (the vertex is a whole parameter line, as
            // the apex of a sphere cut along its seam without a degenerate edge) that line.
            let mut ring: Vec<BoundaryPoint> = Vec::new();
            let n = pieces.len();
            for j in 0..n {
                let (k, piece) = &pieces[j];
                let Some((&last, rest)) = piece.split_last() else {
                    continue;
                };
                ring.extend(rest.iter().map(|&(uv, key, p)| (plane.scale(uv), key, p)));
                let Some(&(q, _, _)) = pieces[(j + 1) % n].1.first() else {
                    continue;
                };
                let (p, key, at) = last;
                let gap = (q[0] - p[0]).hypot(q[1] - p[1]);
                if gap <= closure {
                    continue;
                }
                let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
                let on = |uv: [f64; 2]| plane.point(s, plane.scale(uv));
                let pole = dist(on(p), on(q)) <= tolerance && dist(on(p), on(mid)) <= tolerance;
                if gap.is_nan() || !pole {
                    return Err(Skip::Face(FaceMeshError::OpenInParameters {
                        index,
                        coedge: *k,
                        gap,
                    }));
                }
                for m in 0..POLE_PIECES {
                    let f = m as f64 / POLE_PIECES as f64;
                    let uv = [p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])];
                    ring.push((plane.scale(uv), key, at));
                }
            }
            polygons.push(ring);
        }
        // The face normal: ISO 10303-42 face_bound, the loops run counter-clockwise about
        // the face normal, so the largest loop's signed area in the plane gives its side of
        // the surface (`S_u x S_v` when positive). In a consistent file this is what
        // `same_sense` says; IGES 144 faces carry no such flag, so the loops decide.
        let signed = |ring: &[BoundaryPoint]| {
            let n = ring.len();
            (0..n)
                .map(|k| {
                    let (a, b) = (ring[k].0, ring[(k + 1) % n].0);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
        };
        let largest = polygons
            .iter()
            .map(|r| signed(r))
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(0.0);
        let along = if largest.is_normal() {
            largest > 0.0
        } else {
            face.same_sense
        };
        let region = Region::new(
            polygons
                .iter()
                .map(|r| r.iter().map(|x| x.0).collect())
                .collect(),
        );
        if let Some(index) = region.crossing() {
            return Err(Skip::Face(FaceMeshError::BoundaryCrosses { index }));
        }
        let mut cdt: ConstrainedDelaunayTriangulation<Node> =
            ConstrainedDelaunayTriangulation::new();
        for (index, ring) in polygons.iter().enumerate() {
            let mut handles = Vec::with_capacity(ring.len());
            for &(at, key, p) in ring {
                let id = b.shared(key, p, at, &plane, s);
                handles.push(
                    insert(&mut cdt, at, id)
                        .ok_or(Skip::Face(FaceMeshError::NoParameters { index, coedge: 0 }))?,
                );
            }
            let n = handles.len();
            for k in 0..n {
                let (h0, h1) = (handles[k], handles[(k + 1) % n]);
                if h0 == h1 || cdt.exists_constraint(h0, h1) {
                    continue;
                }
                if !cdt.can_add_constraint(h0, h1) {
                    return Err(Skip::Face(FaceMeshError::BoundaryCrosses { index }));
                }
                cdt.add_constraint(h0, h1);
            }
            if b.positions.len() > max_points {
                return Err(Skip::Stop(TessellationError::TooManyPoints {
                    limit: poll.budget.max_points,
                }));
            }
        }
        // Interior points of the surface's grid, strictly inside and off the boundary.
        let spacing = local_spacing(&grid, &plane);
        // On a closed surface the region may lie across the seam: the grid is tried one
        // period on either side too.
        let shifts = |period: Option<f64>| match period {
            Some(p) => vec![-p, 0.0, p],
            None => vec![0.0],
        };
        let (su, sv) = (shifts(periods[0]), shifts(periods[1]));
        for (i, &[u, v]) in grid.params.iter().enumerate() {
            poll.tick().map_err(Skip::Stop)?;
            for du in &su {
                for dv in &sv {
                    let uv = [u + du, v + dv];
                    let at = plane.scale(uv);
                    if region.inside(at) && region.distance(at) > 0.5 * spacing[i] {
                        b.add_inner(&mut cdt, grid.vertices[i], uv, at);
                    }
                }
            }
            if b.positions.len() > max_points {
                return Err(Skip::Stop(TessellationError::TooManyPoints {
                    limit: poll.budget.max_points,
                }));
            }
        }
        // Refinement rounds.
        let mut unrefined = 0;
        // Triangles (by their corners) that passed: unchanged triangles are not probed again.
        let mut passed: HashSet<[u32; 3]> = HashSet::new();
        for round in 0..=MAX_ROUNDS {
            let mut fixes: Vec<[f64; 2]> = Vec::new();
            let mut seen: HashSet<[u64; 2]> = HashSet::new();
            unrefined = 0;
            let inside = inside_faces(&cdt);
            for f in cdt.inner_faces() {
                poll.tick().map_err(Skip::Stop)?;
                if !inside.get(f.fix().index()).copied().unwrap_or(false) {
                    continue;
                }
                let vs = f.vertices();
                let at = vs.map(|v| [v.position().x, v.position().y]);
                let ids = vs.map(|v| v.data().id as usize);
                if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                    continue;
                }
                let mut corners = vs.map(|v| v.data().id);
                corners.sort_unstable();
                if passed.contains(&corners) {
                    continue;
                }
                // The flat triangle through the surface points at the corners' parameters:
                // boundary corners are edge points, off the surface by up to the edge's
                // tolerance, which no refinement inside the face can change.
                let ps = ids.map(|i| b.on_surface[i]);
                let mut worst = (tolerance, None);
                let mut probe = |w: [f64; 3]| {
                    let q = [
                        w[0] * at[0][0] + w[1] * at[1][0] + w[2] * at[2][0],
                        w[0] * at[0][1] + w[1] * at[1][1] + w[2] * at[2][1],
                    ];
                    let flat: Point3 = std::array::from_fn(|k| {
                        w[0] * ps[0][k] + w[1] * ps[1][k] + w[2] * ps[2][k]
                    });
                    let d = dist(plane.point(s, q), flat);
                    if d > worst.0 || d.is_nan() {
                        worst = (d, Some(q));
                    }
                };
                probe([1.0 / 3.0; 3]);
                for e in f.adjacent_edges() {
                    if e.is_constraint_edge() {
                        continue;
                    }
                    let (a, c) = (e.from().data().id, e.to().data().id);
                    let wa = ids.iter().position(|&x| x == a as usize);
                    let wc = ids.iter().position(|&x| x == c as usize);
                    if let (Some(i), Some(j)) = (wa, wc) {
                        let mut w = [0.0; 3];
                        w[i] = 0.5;
                        w[j] = 0.5;
                        probe(w);
                    }
                }
                match worst {
                    (_, Some(q)) => {
                        unrefined += 1;
                        if seen.insert(q.map(f64::to_bits)) {
                            fixes.push(q);
                        }
                    }
                    (_, None) => {
                        passed.insert(corners);
                    }
                }
            }
            if fixes.is_empty() || round == MAX_ROUNDS {
                break;
            }
            for q in fixes {
                poll.tick().map_err(Skip::Stop)?;
                let uv = plane.unscale(q);
                let p = plane.point(s, q);
                if !p.iter().all(|x| x.is_finite()) {
                    continue;
                }
                b.add_inner(&mut cdt, p, uv, q);
            }
            if b.positions.len() > max_points {
                return Err(Skip::Stop(TessellationError::TooManyPoints {
                    limit: poll.budget.max_points,
                }));
            }
        }
        // The triangles inside the region, counter-clockwise in the scaled plane (spade's
        // order), which is counter-clockwise seen from S_u x S_v.
        let mut triangles = Vec::new();
        let inside = inside_faces(&cdt);
        for f in cdt.inner_faces() {
            if !inside.get(f.fix().index()).copied().unwrap_or(false) {
                continue;
            }
            let vs = f.vertices();
            let t = vs.map(|v| v.data().id as usize);
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                continue; // a pole: two corners are the same point
            }
            triangles.push(if along { t } else { [t[0], t[2], t[1]] });
        }
        b.params = b.params.iter().map(|&uv| plane.wrap(uv)).collect();
        let normals = b
            .params
            .iter()
            .map(|&[u, v]| normal(s, u, v, along))
            .collect();
        Ok((
            Mesh {
                vertices: b.positions,
                params: b.params,
                normals,
                triangles,
            },
            unrefined,
            along,
        ))
    }
}

/// Why a face's mesh stopped: the face is skipped, or the whole work stops.
enum Skip {
    Face(FaceMeshError),
    Stop(TessellationError),
}

/// The face mesh under construction: positions, their parameters, and the boundary points
/// by key (a seam's vertex appears twice in the plane but once here).
#[derive(Default)]
struct Builder {
    positions: Vec<Point3>,
    params: Vec<[f64; 2]>,
    /// The surface at `params` (equal to `positions` except at boundary points).
    on_surface: Vec<Point3>,
    by_key: HashMap<Key, u32>,
}

impl Builder {
    fn shared(
        &mut self,
        key: Key,
        p: Point3,
        at: [f64; 2],
        plane: &Plane,
        s: &NurbsSurface,
    ) -> u32 {
        if let Some(&id) = self.by_key.get(&key) {
            return id;
        }
        let id = self.own(p, plane.unscale(at));
        self.on_surface.pop();
        self.on_surface.push(plane.point(s, at));
        self.by_key.insert(key, id);
        id
    }

    fn own(&mut self, p: Point3, uv: [f64; 2]) -> u32 {
        self.positions.push(p);
        self.on_surface.push(p);
        self.params.push(uv);
        u32::try_from(self.positions.len() - 1).unwrap_or(u32::MAX)
    }

    /// Adds an inner point (on the surface) to the mesh and the triangulation; a point the
    /// triangulation refuses or already holds is forgotten.
    fn add_inner(
        &mut self,
        cdt: &mut ConstrainedDelaunayTriangulation<Node>,
        p: Point3,
        uv: [f64; 2],
        at: [f64; 2],
    ) {
        let id = self.own(p, uv);
        let before = cdt.num_vertices();
        if insert(cdt, at, id).is_none() || cdt.num_vertices() == before {
            self.positions.pop();
            self.on_surface.pop();
            self.params.pop();
        }
    }
}

/// Which triangles lie in the trimmed region, indexed by face index: the even-odd rule
/// walked over the triangulation, from the triangles on its convex hull (outside unless the
/// hull edge is a boundary segment) across each edge, a boundary segment toggling inside
/// and outside. Unlike a point test at each centroid this is exact for the slivers between
/// boundary points that lie on one line of the plane.
fn inside_faces(cdt: &ConstrainedDelaunayTriangulation<Node>) -> Vec<bool> {
    let n = cdt.all_faces().len();
    let mut state: Vec<Option<bool>> = vec![None; n];
    let mut stack = Vec::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                let i = f.fix().index();
                if state[i].is_none() {
                    state[i] = Some(e.is_constraint_edge());
                    stack.push(f.fix());
                }
            }
        }
    }
    while let Some(fixed) = stack.pop() {
        let f = cdt.face(fixed);
        let here = state[fixed.index()].unwrap_or(false);
        for e in f.adjacent_edges() {
            let Some(g) = e.rev().face().as_inner() else {
                continue;
            };
            let j = g.fix().index();
            if state[j].is_none() {
                state[j] = Some(here != e.is_constraint_edge());
                stack.push(g.fix());
            }
        }
    }
    state.into_iter().map(|x| x.unwrap_or(false)).collect()
}

/// Inserts a point unless one is already there (then that one is returned); `None` for a
/// point spade refuses (non-finite or out of its range).
fn insert(
    cdt: &mut ConstrainedDelaunayTriangulation<Node>,
    at: [f64; 2],
    id: u32,
) -> Option<spade::handles::FixedVertexHandle> {
    if !(at[0].is_finite() && at[1].is_finite()) {
        return None;
    }
    let p = Point2::new(at[0], at[1]);
    if let Some(v) = cdt.locate_vertex(p) {
        return Some(v.fix());
    }
    cdt.insert(Node { at: p, id }).ok()
}

/// The parameter plane scaled by the surface's mean speeds, offset to the domain's corner.
struct Plane {
    origin: [f64; 2],
    scale: [f64; 2],
    domain: ((f64, f64), (f64, f64)),
    /// The periods of a surface closed in u or v: a boundary may run past the domain's
    /// end there (a face across the seam), and its parameters are wrapped back.
    periods: [Option<f64>; 2],
}

impl Plane {
    fn of(s: &NurbsSurface) -> Plane {
        let domain = s.domain();
        let ((u0, u1), (v0, v1)) = domain;
        let (mut su, mut sv, mut n) = (0.0, 0.0, 0usize);
        for i in 0..SPEED_SAMPLES {
            for j in 0..SPEED_SAMPLES {
                let u = u0 + (u1 - u0) * (i as f64 + 0.5) / SPEED_SAMPLES as f64;
                let v = v0 + (v1 - v0) * (j as f64 + 0.5) / SPEED_SAMPLES as f64;
                if let Ok(d) = s.derivatives(u, v, 1) {
                    let (a, b) = (norm(d[1][0]), norm(d[0][1]));
                    if a.is_finite() && b.is_finite() {
                        su += a;
                        sv += b;
                        n += 1;
                    }
                }
            }
        }
        let mean = |x: f64| {
            let m = x / n.max(1) as f64;
            if m.is_finite() && m > 0.0 { m } else { 1.0 }
        };
        Plane {
            origin: [u0, v0],
            scale: [mean(su), mean(sv)],
            domain,
            periods: periods(s),
        }
    }

    /// Parameters in the domain: wrapped by the period where the surface is closed,
    /// clamped elsewhere.
    fn wrap(&self, [u, v]: [f64; 2]) -> [f64; 2] {
        let ((u0, u1), (v0, v1)) = self.domain;
        let one = |x: f64, lo: f64, hi: f64, period: Option<f64>| match period {
            Some(p) if p > 0.0 && (x < lo || x > hi) => (lo + (x - lo).rem_euclid(p)).clamp(lo, hi),
            _ => x.clamp(lo, hi),
        };
        [
            one(u, u0, u1, self.periods[0]),
            one(v, v0, v1, self.periods[1]),
        ]
    }

    fn scale(&self, uv: [f64; 2]) -> [f64; 2] {
        [
            (uv[0] - self.origin[0]) * self.scale[0],
            (uv[1] - self.origin[1]) * self.scale[1],
        ]
    }

    fn unscale(&self, at: [f64; 2]) -> [f64; 2] {
        [
            at[0] / self.scale[0] + self.origin[0],
            at[1] / self.scale[1] + self.origin[1],
        ]
    }

    /// The surface point at a scaled point (parameters kept in the domain).
    fn point(&self, s: &NurbsSurface, at: [f64; 2]) -> Point3 {
        let [u, v] = self.wrap(self.unscale(at));
        s.point_at_unchecked(u, v)
    }
}

/// The periods of a surface closed in u or v (its boundary curves at both ends of that
/// direction coincide, within 1e-9 of its size at 5 points): `(u1 - u0)` / `(v1 - v0)`.
fn periods(s: &NurbsSurface) -> [Option<f64>; 2] {
    let ((u0, u1), (v0, v1)) = s.domain();
    let size = crate::nurbs::bounding_box_diagonal(s.control_points().as_slice());
    let closes = |along_u: bool| {
        (0..=4).all(|k| {
            let t = k as f64 / 4.0;
            let (a, b) = if along_u {
                let v = v0 + (v1 - v0) * t;
                (s.point_at_unchecked(u0, v), s.point_at_unchecked(u1, v))
            } else {
                let u = u0 + (u1 - u0) * t;
                (s.point_at_unchecked(u, v0), s.point_at_unchecked(u, v1))
            };
            dist(a, b) <= 1e-9 * size
        })
    };
    [
        closes(true).then_some(u1 - u0),
        closes(false).then_some(v1 - v0),
    ]
}

/// Whether two uses of an edge carry the same parameter-space curve (at the ends and the
/// middle of the edge's range, within `closure`).
fn same_pcurve(a: &super::Coedge, b: &super::Coedge, m: &Model, closure: f64) -> bool {
    let (Some(pa), Some(pb), Some(e)) = (&a.pcurve, &b.pcurve, m.edges.get(a.edge.0)) else {
        return false;
    };
    let (r0, r1) = e.range;
    [r0, 0.5 * (r0 + r1), r1].iter().all(|&t| {
        let (x, y) = (
            pa.point_at_unchecked(t.clamp(pa.domain().0, pa.domain().1)),
            pb.point_at_unchecked(t.clamp(pb.domain().0, pb.domain().1)),
        );
        (x[0] - y[0]).hypot(x[1] - y[1]) <= closure
    })
}

/// On a closed surface a point of the seam has two parameters; a boundary point takes the
/// one nearest the point before it, so the boundary stays on one side of the seam.
fn unwrap(uv: [f64; 2], guess: Option<(f64, f64)>, periods: [Option<f64>; 2]) -> [f64; 2] {
    let Some((gu, gv)) = guess else { return uv };
    let near = |x: f64, g: f64, period: Option<f64>| match period {
        Some(p) if p > 0.0 => [x - p, x, x + p]
            .into_iter()
            .min_by(|a, b| (a - g).abs().total_cmp(&(b - g).abs()))
            .unwrap_or(x),
        _ => x,
    };
    [near(uv[0], gu, periods[0]), near(uv[1], gv, periods[1])]
}

/// The unit face normal at `(u, v)`: `S_u x S_v`, reversed without `same_sense`; zero at a
/// pole.
fn normal(s: &NurbsSurface, u: f64, v: f64, same_sense: bool) -> Point3 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let Ok(d) = s.derivatives(u.clamp(u0, u1), v.clamp(v0, v1), 1) else {
        return [0.0; 3];
    };
    let n = cross(d[1][0], d[0][1]);
    let l = norm(n);
    let sign = if same_sense { 1.0 } else { -1.0 };
    if l > 0.0 && l.is_finite() {
        n.map(|x| sign * x / l)
    } else {
        [0.0; 3]
    }
}

/// The shortest grid edge at each vertex of the surface's grid, in the scaled plane.
fn local_spacing(grid: &Mesh, plane: &Plane) -> Vec<f64> {
    let mut h = vec![f64::INFINITY; grid.params.len()];
    for t in &grid.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (pa, pb) = (plane.scale(grid.params[a]), plane.scale(grid.params[b]));
            let d = (pa[0] - pb[0]).hypot(pa[1] - pb[1]);
            h[a] = h[a].min(d);
            h[b] = h[b].min(d);
        }
    }
    h
}

/// The trimmed region in the scaled plane: the loops' segments, bucketed in horizontal
/// bands for the even-odd test and the distance to the boundary.
struct Region {
    segments: Vec<[[f64; 2]; 2]>,
    /// The loop of each segment.
    owner: Vec<usize>,
    low: f64,
    band: f64,
    bands: Vec<Vec<u32>>,
}

impl Region {
    fn new(loops: Vec<Vec<[f64; 2]>>) -> Region {
        let mut segments = Vec::new();
        let mut owner = Vec::new();
        for (index, ring) in loops.iter().enumerate() {
            let n = ring.len();
            for k in 0..n {
                segments.push([ring[k], ring[(k + 1) % n]]);
                owner.push(index);
            }
        }
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &segments {
            for p in s {
                low = low.min(p[1]);
                high = high.max(p[1]);
            }
        }
        let count = ((segments.len() as f64).sqrt() as usize).clamp(1, 1024);
        let band = ((high - low) / count as f64).max(f64::MIN_POSITIVE);
        let mut bands = vec![Vec::new(); count];
        if low.is_finite() && high.is_finite() {
            for (i, s) in segments.iter().enumerate() {
                let (a, b) = (s[0][1].min(s[1][1]), s[0][1].max(s[1][1]));
                let (ba, bb) = (
                    Self::index(low, band, count, a),
                    Self::index(low, band, count, b),
                );
                for list in &mut bands[ba..=bb] {
                    list.push(u32::try_from(i).unwrap_or(u32::MAX));
                }
            }
        }
        Region {
            segments,
            owner,
            low,
            band,
            bands,
        }
    }

    fn index(low: f64, band: f64, count: usize, y: f64) -> usize {
        let k = ((y - low) / band).floor();
        if k.is_nan() || k < 0.0 {
            0
        } else {
            (k as usize).min(count - 1)
        }
    }

    /// The loop of the first segment found crossing another in its interior (segments
    /// that share an end point do not count): orientation tests on the pairs of segments
    /// of each band.
    fn crossing(&self) -> Option<usize> {
        let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            let x = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if x > 0.0 {
                1
            } else if x < 0.0 {
                -1
            } else {
                0
            }
        };
        for list in &self.bands {
            for (n, &i) in list.iter().enumerate() {
                let [a, b] = self.segments[i as usize];
                for &j in &list[n + 1..] {
                    let [c, d] = self.segments[j as usize];
                    if a == c || a == d || b == c || b == d {
                        continue;
                    }
                    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
                    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
                    if o1 * o2 < 0 && o3 * o4 < 0 {
                        return Some(self.owner[i as usize]);
                    }
                }
            }
        }
        None
    }

    /// Even-odd rule: a ray towards +x crosses the boundary an odd number of times.
    fn inside(&self, p: [f64; 2]) -> bool {
        if !(p[1] >= self.low && p[1] <= self.low + self.band * self.bands.len() as f64) {
            return false;
        }
        let k = Self::index(self.low, self.band, self.bands.len(), p[1]);
        let mut odd = false;
        for &i in &self.bands[k] {
            let [a, b] = self.segments[i as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    odd = !odd;
                }
            }
        }
        odd
    }

    /// Distance from `p` to the nearest segment (infinite with no segment in reach of the
    /// bands searched: those within one band's height, widened until one is found).
    fn distance(&self, p: [f64; 2]) -> f64 {
        let count = self.bands.len();
        let k = Self::index(self.low, self.band, count, p[1]);
        let mut best = f64::INFINITY;
        let mut reach = 1usize;
        loop {
            let (a, b) = (k.saturating_sub(reach), (k + reach).min(count - 1));
            for list in &self.bands[a..=b] {
                for &i in list {
                    best = best.min(segment_distance(p, self.segments[i as usize]));
                }
            }
            // Every segment closer than `best` lies in the bands within `best` of p.
            let covered = (reach as f64 - 1.0) * self.band;
            if best <= covered || (a == 0 && b == count - 1) {
                return best;
            }
            reach = (reach * 2).min(count);
        }
    }
}

fn segment_distance(p: [f64; 2], [a, b]: [[f64; 2]; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}
