//! # The topology of a part: vertices, edges, loops, faces, shells, solids, assemblies
//!
//! The boundary representation of ISO 10303-42 clause 5 (topology: vertex, edge, oriented
//! edge, loop, face, shell, solid) and of IGES 5.3 section 4.49 (186 manifold solid B-rep
//! with 502/504/508/510/514), over the exact NURBS geometry of [`crate::nurbs`]: every edge
//! carries a NURBS curve, every face a NURBS surface. Readers of both formats build a
//! [`Model`]; writers walk it.
//!
//! **Layering:** imports only [`crate::nurbs`]; `exchange` imports this module and turns its
//! [`TopologyError`]s into located diagnostics (the ids here are indices; the reader knows
//! which file entity each came from).
//!
//! Everything is built through checked constructors, so a [`Model`] never holds a loop that
//! does not close, an edge whose curve misses its vertices, or a shell that claims to be
//! closed and is not:
//! - [`Model::add_edge`]: the curve at the ends of the edge's range lies within tolerance of
//!   its vertices (ISO 10303-42 clause 5, edge_curve: `edge_start`/`edge_end` lie on `edge_geometry`).
//! - [`Model::add_face`]: each loop's oriented edges chain head to tail through shared
//!   vertices (clause 5, edge_loop: each edge ends where the next starts), and each parameter-space curve
//!   agrees with its 3-D edge curve (clause 4, surface_curve / pcurve: surface(pcurve(t)) =
//!   curve(t) within the edge's tolerance; the deviation found is kept).
//! - [`Model::add_shell`]: a shell declared closed uses every edge exactly twice, once in
//!   each direction (clause 5, closed_shell: a connected face set without
//!   boundary, every oriented edge matched by its reverse).
//! - [`Model::add_solid`]: the outer shell and the voids are closed shells.
//! - [`Assembly`]: instances of parts under affine placements; [`Model::flatten`] composes the
//!   placements without recursion and refuses cycles.
//! - [`Model::sew`]: loose faces into shells and solids (shared vertices and edges).
//! - [`Model::measure_face`], [`Model::solid_volume`]: area, centroid and volume over the
//!   trimmed regions, by Green's theorem along the pcurves.
//! - [`Model::mesh`]: triangle meshes of the trimmed faces within a chord tolerance, every
//!   edge tessellated once and shared by its faces (watertight closed shells).

mod assembly;
mod check;
mod error;
mod measure;
mod mesh;
mod pcurve;
mod sew;

pub use assembly::{Assembly, Copied, Instance, Part, Placed};
pub use error::TopologyError;
pub use measure::{FACE_EVALUATIONS, FaceMeasure, MODEL_EVALUATIONS, MeasureError, Totals};
pub use mesh::{FaceMeshError, MAX_ROUNDS, PartMesh};
pub use pcurve::{
    EdgePcurve, PcurveMethod, SeamPlan, edge_pcurve, exact_pcurve, loop_counter_clockwise,
    moved_seams, same_trace, seam_side, seam_sides_by_continuity, seam_splits,
};
pub use sew::Sewing;

use crate::nurbs::{NurbsCurve, NurbsSurface, Point3};

/// Index of a vertex in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexId(pub usize);
/// Index of an edge in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EdgeId(pub usize);
/// Index of a face in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FaceId(pub usize);
/// Index of a shell in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ShellId(pub usize);
/// Index of a solid in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SolidId(pub usize);
/// Index of an assembly in its [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AssemblyId(pub usize);

/// A point of the boundary (ISO 10303-42 vertex_point).
#[derive(Debug, Clone, PartialEq)]
pub struct Vertex {
    /// Where it is.
    pub point: Point3,
    /// How far the geometry meeting here may be from `point`.
    pub tolerance: f64,
}

/// A bounded piece of a curve between two vertices (ISO 10303-42 edge_curve; IGES 504).
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// The exact 3-D curve.
    pub curve: NurbsCurve,
    /// The part of the curve's parameter range the edge uses, `start < end`; the edge runs
    /// from `curve(range.0)` at `start` to `curve(range.1)` at `end`.
    pub range: (f64, f64),
    /// Vertex at `range.0`.
    pub start: VertexId,
    /// Vertex at `range.1`.
    pub end: VertexId,
    /// How far the curve may be from its vertices (and its pcurves from it).
    pub tolerance: f64,
}

/// An edge as a loop uses it (ISO 10303-42 oriented_edge; IGES 508 edge with its
/// orientation flag), with the edge's curve in the face's parameter space when known.
#[derive(Debug, Clone, PartialEq)]
pub struct Coedge {
    /// The edge.
    pub edge: EdgeId,
    /// `true`: the loop runs from the edge's start to its end.
    pub forward: bool,
    /// The edge in the face surface's `(u, v)` space, parameterised like the edge's curve
    /// (ISO 10303-42 surface_curve: the associated geometry shares the curve's parameter).
    pub pcurve: Option<NurbsCurve>,
    /// Largest distance found between `surface(pcurve(t))` and `curve(t)` over the edge's
    /// range. Given with the pcurve when it was measured as the pcurve was made
    /// ([`edge_pcurve`], at more points than the face check takes): the face check of
    /// [`Model::add_face`] then compares it with the edge's tolerance; `None` has the face
    /// check sample it.
    pub pcurve_deviation: Option<f64>,
}

/// A closed chain of coedges (ISO 10303-42 edge_loop / face_bound; IGES 508).
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// The coedges, head to tail.
    pub coedges: Vec<Coedge>,
    /// `true` for the outer boundary (face_outer_bound), `false` for a hole.
    pub outer: bool,
}

/// A bounded region of a surface (ISO 10303-42 advanced_face / face_surface; IGES 510 or
/// 144).
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The exact surface.
    pub surface: NurbsSurface,
    /// Its boundaries; none for a face bounded by its surface's own domain.
    pub loops: Vec<Loop>,
    /// `true` when the face normal is the surface normal (ISO 10303-42 `same_sense`).
    pub same_sense: bool,
    /// The vertices its vertex loops name (ISO 10303-42 vertex_loop; an IGES 508 loop of a
    /// vertex use): degenerate bounds at a cone's apex or a sphere's pole, which bound
    /// nothing in the surface's parameters and use no edge. Set after [`Model::add_face`].
    pub vertex_loops: Vec<VertexId>,
}

/// A connected set of faces (ISO 10303-42 open_shell / closed_shell; IGES 514).
#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// Faces with their orientation in the shell (`true` = as the face is).
    pub faces: Vec<(FaceId, bool)>,
    /// Whether every edge is used exactly twice in opposite directions (checked).
    pub closed: bool,
}

/// A solid bounded by a closed outer shell and closed voids (ISO 10303-42
/// manifold_solid_brep / brep_with_voids; IGES 186).
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// The outer boundary.
    pub outer: ShellId,
    /// Inner boundaries (cavities).
    pub voids: Vec<ShellId>,
}

/// Everything a file's boundary representation holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Model {
    /// All vertices.
    pub vertices: Vec<Vertex>,
    /// All edges.
    pub edges: Vec<Edge>,
    /// All faces.
    pub faces: Vec<Face>,
    /// All shells.
    pub shells: Vec<Shell>,
    /// All solids.
    pub solids: Vec<Solid>,
    /// All assemblies.
    pub assemblies: Vec<Assembly>,
}

impl Model {
    /// An empty model.
    pub fn new() -> Self {
        Self::default()
    }

    /// The largest tolerance of a vertex or an edge (0 for a model without them): how far
    /// apart two points of the model may be and still be the same point, which a writer
    /// declares so that a reader joins what this model joins.
    pub fn max_tolerance(&self) -> f64 {
        let vertices = self.vertices.iter().map(|v| v.tolerance);
        let edges = self.edges.iter().map(|e| e.tolerance);
        vertices.chain(edges).fold(0.0, f64::max)
    }

    /// Adds a vertex. Refuses a non-finite point or a negative/non-finite tolerance.
    pub fn add_vertex(&mut self, point: Point3, tolerance: f64) -> Result<VertexId, TopologyError> {
        if !(point.iter().all(|c| c.is_finite()) && tolerance >= 0.0 && tolerance.is_finite()) {
            return Err(TopologyError::BadVertex { point, tolerance });
        }
        self.vertices.push(Vertex { point, tolerance });
        Ok(VertexId(self.vertices.len() - 1))
    }

    /// Adds an edge after checking that its range lies in the curve's domain and that the
    /// curve at the range's ends is within tolerance of the vertices (the larger of the
    /// edge's and the vertex's tolerance).
    pub fn add_edge(
        &mut self,
        curve: NurbsCurve,
        range: (f64, f64),
        start: VertexId,
        end: VertexId,
        tolerance: f64,
    ) -> Result<EdgeId, TopologyError> {
        let id = EdgeId(self.edges.len());
        check::edge(self, id, &curve, range, start, end, tolerance)?;
        self.edges.push(Edge {
            curve,
            range,
            start,
            end,
            tolerance,
        });
        Ok(id)
    }

    /// Splits an edge at the parameter `t` strictly inside its range: the edge keeps
    /// `[range.0, t]` and ends at a new vertex at `curve(t)`; a new edge on the same curve
    /// takes `[t, range.1]` from that vertex to the old end. Every coedge of the edge in the
    /// model's faces becomes two (in the order its loop runs), their pcurves cut at `t`
    /// exactly ([`NurbsCurve::piece`], A5.1: a pcurve shares the edge curve's parameter).
    /// The geometry is unchanged; the model gains one vertex and one edge. Returns them.
    ///
    /// Errors: a missing edge, or `t` not strictly inside the range or not splitting every
    /// pcurve (nothing is changed then).
    pub fn split_edge(
        &mut self,
        edge: EdgeId,
        t: f64,
    ) -> Result<(VertexId, EdgeId), TopologyError> {
        let e = self.edges.get(edge.0).ok_or(TopologyError::Missing {
            what: "edge",
            index: edge.0,
        })?;
        let (a, b) = e.range;
        let bad = TopologyError::EdgeRange {
            edge,
            range: (a, t),
            domain: (a, b),
        };
        if !(t > a && t < b) {
            return Err(bad);
        }
        // Every pcurve is cut first, so that a failure changes nothing.
        let mut cut: Vec<(usize, usize, usize, [Option<NurbsCurve>; 2])> = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            for (l, lp) in face.loops.iter().enumerate() {
                for (k, c) in lp.coedges.iter().enumerate() {
                    if c.edge == edge {
                        cut.push((f, l, k, split_pcurve(c, (a, t, b)).ok_or(bad.clone())?));
                    }
                }
            }
        }
        let point = e.curve.point_at(t).map_err(|_| bad.clone())?;
        let (curve, end, tolerance) = (e.curve.clone(), e.end, e.tolerance);
        let middle = self.add_vertex(point, tolerance)?;
        let second = EdgeId(self.edges.len());
        self.edges.push(Edge {
            curve,
            range: (t, b),
            start: middle,
            end,
            tolerance,
        });
        let first = &mut self.edges[edge.0];
        first.range = (a, t);
        first.end = middle;
        // Coedges from the last, so that the indices of the earlier ones stay valid.
        for (f, l, k, [p1, p2]) in cut.into_iter().rev() {
            let coedges = &mut self.faces[f].loops[l].coedges;
            let c = coedges[k].clone();
            coedges.splice(k..=k, split_coedge(&c, second, p1, p2));
        }
        Ok((middle, second))
    }

    /// The loops with every coedge of `edge` replaced by the two coedges of its halves after
    /// [`split_edge`](Self::split_edge) made `second` of it at `t`: for loops not yet in a
    /// face. `None` (the loops unchanged) if a pcurve does not split.
    pub fn split_coedges(&self, loops: &mut [Loop], edge: EdgeId, second: EdgeId) -> Option<()> {
        let (a, t) = self.edges.get(edge.0)?.range;
        let b = self.edges.get(second.0)?.range.1;
        let mut out: Vec<Vec<Coedge>> = Vec::with_capacity(loops.len());
        for l in loops.iter() {
            let mut coedges = Vec::with_capacity(l.coedges.len() + 1);
            for c in &l.coedges {
                if c.edge == edge {
                    let [p1, p2] = split_pcurve(c, (a, t, b))?;
                    coedges.extend(split_coedge(c, second, p1, p2));
                } else {
                    coedges.push(c.clone());
                }
            }
            out.push(coedges);
        }
        for (l, coedges) in loops.iter_mut().zip(out) {
            l.coedges = coedges;
        }
        Some(())
    }

    /// The vertices an edge is traversed from and to by a coedge.
    pub fn coedge_ends(&self, c: &Coedge) -> Option<(VertexId, VertexId)> {
        let e = self.edges.get(c.edge.0)?;
        Some(if c.forward {
            (e.start, e.end)
        } else {
            (e.end, e.start)
        })
    }

    /// The index of the loop that bounds the others, for a face whose bounds do not say
    /// which one is outer (ISO 10303-42 face_bound: a face_outer_bound is optional, and
    /// several plain face_bounds leave the outer one to the geometry). The outer loop is the
    /// one whose box contains the boxes of all the others: in `(u, v)` when every coedge has
    /// a pcurve, else in model space (the edges' curves). `None` when no loop contains the
    /// others (a face between two loops that both wrap around a periodic surface).
    pub fn outer_loop(&self, loops: &[Loop]) -> Option<usize> {
        const SAMPLES: usize = 16;
        let in_uv = loops
            .iter()
            .all(|l| l.coedges.iter().all(|c| c.pcurve.is_some()));
        let boxes: Vec<([f64; 3], [f64; 3])> = loops
            .iter()
            .map(|l| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for c in &l.coedges {
                    let Some(e) = self.edges.get(c.edge.0) else {
                        continue;
                    };
                    let curve = match (&c.pcurve, in_uv) {
                        (Some(p), true) => p,
                        _ => &e.curve,
                    };
                    for k in 0..=SAMPLES {
                        let t = e.range.0 + (e.range.1 - e.range.0) * k as f64 / SAMPLES as f64;
                        let x = curve.point_at_unchecked(t);
                        for d in 0..x.len().min(3) {
                            if x[d].is_finite() {
                                lo[d] = lo[d].min(x[d]);
                                hi[d] = hi[d].max(x[d]);
                            }
                        }
                    }
                }
                (lo, hi)
            })
            .collect();
        let size = |b: &([f64; 3], [f64; 3])| {
            (0..3)
                .map(|d| (b.1[d] - b.0[d]).max(0.0))
                .filter(|x| x.is_finite())
                .fold(0.0_f64, |a, x| a.max(x))
        };
        let (best, outer) = boxes
            .iter()
            .enumerate()
            .max_by(|a, b| size(a.1).total_cmp(&size(b.1)))?;
        let slack = 1e-9 * size(outer).max(f64::MIN_POSITIVE);
        let contains = boxes.iter().enumerate().all(|(i, b)| {
            i == best
                || (0..3).all(|d| {
                    !(b.0[d].is_finite() && b.1[d].is_finite())
                        || (b.0[d] >= outer.0[d] - slack && b.1[d] <= outer.1[d] + slack)
                })
        });
        contains.then_some(best)
    }

    /// Adds a face after checking every loop (closure through shared vertices, pcurves
    /// against their edges); the pcurve deviations found are stored on the coedges.
    pub fn add_face(
        &mut self,
        surface: NurbsSurface,
        loops: Vec<Loop>,
        same_sense: bool,
    ) -> Result<FaceId, TopologyError> {
        self.try_add_face(surface, loops, same_sense)
            .map_err(|r| r.error)
    }

    /// [`Model::add_face`], giving the loops back when the check refuses them, for a caller
    /// that retries without what was refused (a pcurve that deviates). The loops are as the
    /// check left them: the coedges checked before the refusal carry the deviations
    /// measured, which a later check takes as measured.
    pub fn try_add_face(
        &mut self,
        surface: NurbsSurface,
        mut loops: Vec<Loop>,
        same_sense: bool,
    ) -> Result<FaceId, RefusedFace> {
        let id = FaceId(self.faces.len());
        for index in 0..loops.len() {
            let Some(l) = loops.get_mut(index) else { break };
            if let Err(error) = check::face_loop(self, id, index, &surface, l) {
                return Err(RefusedFace { error, loops });
            }
        }
        self.faces.push(Face {
            surface,
            loops,
            same_sense,
            vertex_loops: Vec::new(),
        });
        Ok(id)
    }

    /// Adds a shell; when `declared_closed` the shell must use every edge exactly twice in
    /// opposite directions, else the error names the edges that break it.
    pub fn add_shell(
        &mut self,
        faces: Vec<(FaceId, bool)>,
        declared_closed: bool,
    ) -> Result<ShellId, TopologyError> {
        let id = ShellId(self.shells.len());
        let closed = check::shell(self, id, &faces, declared_closed)?;
        self.shells.push(Shell { faces, closed });
        Ok(id)
    }

    /// Adds a solid; every shell must exist and be closed.
    pub fn add_solid(
        &mut self,
        outer: ShellId,
        voids: Vec<ShellId>,
    ) -> Result<SolidId, TopologyError> {
        for &s in std::iter::once(&outer).chain(&voids) {
            match self.shells.get(s.0) {
                None => {
                    return Err(TopologyError::Missing {
                        what: "shell",
                        index: s.0,
                    });
                }
                Some(shell) if !shell.closed => {
                    return Err(TopologyError::SolidShellOpen { shell: s });
                }
                Some(_) => {}
            }
        }
        self.solids.push(Solid { outer, voids });
        Ok(SolidId(self.solids.len() - 1))
    }
}

/// A face [`Model::try_add_face`] refused: why, and its loops.
#[derive(Debug)]
pub struct RefusedFace {
    /// What the check found.
    pub error: TopologyError,
    /// The face's loops, as the check left them.
    pub loops: Vec<Loop>,
}

/// A coedge's pcurve cut at `t` of its edge's range `[a, b]`: `[None, None]` without one.
fn split_pcurve(c: &Coedge, (a, t, b): (f64, f64, f64)) -> Option<[Option<NurbsCurve>; 2]> {
    match &c.pcurve {
        None => Some([None, None]),
        Some(p) => Some([Some(p.piece(a, t).ok()?), Some(p.piece(t, b).ok()?)]),
    }
}

/// The two coedges that replace `c` once its edge is split ([`Model::split_edge`]): the
/// first half (`c.edge`, kept) then the second (`second`) when the loop runs with the edge,
/// the other way round otherwise. The deviation found over the whole range bounds each half.
fn split_coedge(
    c: &Coedge,
    second: EdgeId,
    p1: Option<NurbsCurve>,
    p2: Option<NurbsCurve>,
) -> [Coedge; 2] {
    let half = |edge: EdgeId, pcurve: Option<NurbsCurve>| Coedge {
        edge,
        forward: c.forward,
        pcurve,
        pcurve_deviation: c.pcurve_deviation,
    };
    let (h1, h2) = (half(c.edge, p1), half(second, p2));
    if c.forward { [h1, h2] } else { [h2, h1] }
}
