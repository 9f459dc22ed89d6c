//! Assemblies: named instances of parts under affine placements (ISO 10303-44 product
//! structure with ISO 10303-42 item_defined_transformation / mapped_item; IGES 5.3 408
//! singular subfigure instances with 124 transforms).

use std::collections::HashMap;

use super::{
    AssemblyId, Coedge, Edge, EdgeId, Face, FaceId, Loop, Model, Shell, ShellId, Solid, SolidId,
    TopologyError, Vertex, VertexId,
};
use crate::nurbs::transform::{Affine, IDENTITY, apply, compose};

/// What an instance places.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Part {
    /// A solid.
    Solid(SolidId),
    /// A shell (a surface model).
    Shell(ShellId),
    /// A single face.
    Face(FaceId),
    /// A free curve (an edge outside any face).
    Edge(EdgeId),
    /// Another assembly.
    Assembly(AssemblyId),
}

/// One use of a part inside an assembly.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The instance's name (STEP NEXT_ASSEMBLY_USAGE_OCCURRENCE name, IGES label).
    pub name: Option<String>,
    /// Where the part goes: parent coordinates = placement applied to the part's own.
    pub placement: Affine,
    /// The part placed.
    pub part: Part,
}

/// A named set of instances (STEP product with its components; IGES 308 subfigure).
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// The product name.
    pub name: String,
    /// Its components.
    pub instances: Vec<Instance>,
}

/// A leaf of a flattened assembly: a part (never an assembly) in root coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    /// The part.
    pub part: Part,
    /// The placement composed from the root down.
    pub placement: Affine,
    /// Instance indices from the root to this leaf.
    pub path: Vec<usize>,
}

impl Model {
    /// Adds an assembly. Its instances may name assemblies added later; [`Model::flatten`]
    /// checks them.
    pub fn add_assembly(&mut self, assembly: Assembly) -> AssemblyId {
        self.assemblies.push(assembly);
        AssemblyId(self.assemblies.len() - 1)
    }

    /// Every leaf part under `root` with its composed placement, depth first in instance
    /// order. Uses an explicit stack (the nesting depth is the file's to choose, so no
    /// recursion), refuses assemblies that contain themselves, and stops at `max_depth`
    /// levels or `max_instances` leaves (a shared sub-assembly multiplies its instances).
    pub fn flatten(
        &self,
        root: AssemblyId,
        max_depth: usize,
        max_instances: usize,
    ) -> Result<Vec<Placed>, TopologyError> {
        let missing = |a: AssemblyId| TopologyError::Missing {
            what: "assembly",
            index: a.0,
        };
        self.assemblies.get(root.0).ok_or_else(|| missing(root))?;
        enum Frame {
            Expand(AssemblyId, Affine, Vec<AssemblyId>, Vec<usize>),
            Leaf(Part, Affine, Vec<usize>),
        }
        let mut out = Vec::new();
        let mut stack = vec![Frame::Expand(root, IDENTITY, vec![root], Vec::new())];
        while let Some(frame) = stack.pop() {
            let (a, placement, chain, path) = match frame {
                Frame::Leaf(part, placement, path) => {
                    if out.len() >= max_instances {
                        return Err(TopologyError::AssemblyTooLarge {
                            root,
                            what: "instances",
                            limit: max_instances,
                        });
                    }
                    out.push(Placed {
                        part,
                        placement,
                        path,
                    });
                    continue;
                }
                Frame::Expand(a, placement, chain, path) => (a, placement, chain, path),
            };
            let asm = self.assemblies.get(a.0).ok_or_else(|| missing(a))?;
            // Pushed in reverse so that they pop in instance order (depth first).
            for (i, inst) in asm.instances.iter().enumerate().rev() {
                let world = compose(&placement, &inst.placement);
                let mut path = path.clone();
                path.push(i);
                match inst.part {
                    Part::Assembly(child) => {
                        let mut chain = chain.clone();
                        chain.push(child);
                        if chain[..chain.len() - 1].contains(&child) {
                            return Err(TopologyError::AssemblyCycle { chain });
                        }
                        if chain.len() > max_depth {
                            return Err(TopologyError::AssemblyTooLarge {
                                root,
                                what: "levels",
                                limit: max_depth,
                            });
                        }
                        stack.push(Frame::Expand(child, world, chain, path));
                    }
                    part => stack.push(Frame::Leaf(part, world, path)),
                }
            }
        }
        Ok(out)
    }
}

/// Which items of the source model a placed copy came from, index-aligned with the items
/// [`Model::place`] appended to the target (`vertices[k]` is the source vertex of the k-th
/// vertex appended, and so on).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Copied {
    /// Source vertices.
    pub vertices: Vec<VertexId>,
    /// Source edges.
    pub edges: Vec<EdgeId>,
    /// Source faces.
    pub faces: Vec<FaceId>,
    /// Source shells.
    pub shells: Vec<ShellId>,
    /// Source solids.
    pub solids: Vec<SolidId>,
}

/// Checks that `m` is finite with a linear part of positive determinant, and returns the
/// factor by which it may stretch a length at most (the Frobenius norm of the linear part,
/// an upper bound of its largest singular value).
fn stretch(m: &Affine) -> Result<f64, TopologyError> {
    let invalid = |reason: &str| TopologyError::PlacementInvalid {
        placement: *m,
        reason: reason.to_owned(),
    };
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Err(invalid("not finite"));
    }
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if det.is_nan() || det <= 0.0 {
        return Err(invalid(
            "the determinant of its linear part is not positive (a mirror or a collapse)",
        ));
    }
    let frobenius = (0..3)
        .flat_map(|r| (0..3).map(move |c| (r, c)))
        .map(|(r, c)| m[r][c] * m[r][c])
        .sum::<f64>()
        .sqrt();
    Ok(frobenius)
}

impl Model {
    /// The vertices, edges, faces and shells `part` uses (each once), in the order a copy
    /// visits them; `None` for an assembly or a missing item.
    fn part_items(&self, part: Part) -> Option<(Vec<ShellId>, Vec<FaceId>, Vec<EdgeId>)> {
        let mut shells: Vec<ShellId> = Vec::new();
        let mut faces: Vec<FaceId> = Vec::new();
        let mut edges: Vec<EdgeId> = Vec::new();
        match part {
            Part::Solid(s) => {
                let solid = self.solids.get(s.0)?;
                shells.push(solid.outer);
                shells.extend(&solid.voids);
            }
            Part::Shell(s) => shells.push(s),
            Part::Face(f) => faces.push(f),
            Part::Edge(e) => edges.push(e),
            Part::Assembly(_) => return None,
        }
        let mut seen_faces = std::collections::HashSet::new();
        faces.retain(|f| seen_faces.insert(*f));
        for s in &shells {
            for &(f, _) in &self.shells.get(s.0)?.faces {
                if seen_faces.insert(f) {
                    faces.push(f);
                }
            }
        }
        let mut seen_edges: std::collections::HashSet<EdgeId> = edges.iter().copied().collect();
        for f in &faces {
            for l in &self.faces.get(f.0)?.loops {
                for c in &l.coedges {
                    if seen_edges.insert(c.edge) {
                        edges.push(c.edge);
                    }
                }
            }
        }
        Some((shells, faces, edges))
    }

    /// How many items copying `part` with [`Model::place`] appends (vertices, edges, faces,
    /// shells and solids), to check a budget before copying.
    pub fn part_size(&self, part: Part) -> Result<usize, TopologyError> {
        let (shells, faces, edges) = self.part_items(part).ok_or(TopologyError::Missing {
            what: "part",
            index: 0,
        })?;
        let mut vertices = std::collections::HashSet::new();
        for e in &edges {
            if let Some(edge) = self.edges.get(e.0) {
                vertices.insert(edge.start);
                vertices.insert(edge.end);
            }
        }
        for f in &faces {
            if let Some(face) = self.faces.get(f.0) {
                vertices.extend(face.vertex_loops.iter().copied());
            }
        }
        let solids = usize::from(matches!(part, Part::Solid(_)));
        Ok(vertices.len() + edges.len() + faces.len() + shells.len() + solids)
    }

    /// Appends a copy of `part` (a solid, shell, face or free edge with everything it uses)
    /// to `target`, its geometry mapped exactly by `placement` (control points transformed,
    /// weights and knots kept: NURBS affine invariance, NURBS Book section 4.4; the
    /// parameter-space curves stay as they are, the surfaces keeping their parameters), and
    /// returns the copy and the source of each appended item. Tolerances grow with the
    /// placement's stretch. Shared edges and vertices of the part stay shared in the copy.
    /// Refuses an assembly (flatten it first with [`Model::flatten`]), a missing item, and
    /// a placement that is not finite or would mirror (ISO 10303-42 axis placements never
    /// do; a mirrored solid would need its loops reversed).
    pub fn place(
        &self,
        part: Part,
        placement: &Affine,
        target: &mut Model,
    ) -> Result<(Part, Copied), TopologyError> {
        let grow = stretch(placement)?.max(1.0);
        let missing = |what: &'static str, index: usize| TopologyError::Missing { what, index };
        let geometry = |e: crate::nurbs::GeometryError| TopologyError::PlacementInvalid {
            placement: *placement,
            reason: e.to_string(),
        };
        let (shells, faces, edges) = self.part_items(part).ok_or_else(|| missing("part", 0))?;
        let mut copied = Copied::default();
        // Build the copies first, then append them all (nothing appended on an error).
        let mut vertices = VertexCopies {
            base: target.vertices.len(),
            map: HashMap::new(),
            new: Vec::new(),
            sources: Vec::new(),
        };
        let mut edge_map: HashMap<EdgeId, EdgeId> = HashMap::new();
        let mut new_edges = Vec::with_capacity(edges.len());
        for &e in &edges {
            let edge = self.edges.get(e.0).ok_or_else(|| missing("edge", e.0))?;
            let mut ends = [edge.start, edge.end];
            for v in &mut ends {
                *v = vertices.copy(self, *v, placement, grow)?;
            }
            edge_map.insert(e, EdgeId(target.edges.len() + new_edges.len()));
            new_edges.push(Edge {
                curve: edge.curve.transform(placement).map_err(geometry)?,
                range: edge.range,
                start: ends[0],
                end: ends[1],
                tolerance: edge.tolerance * grow,
            });
            copied.edges.push(e);
        }
        let mut face_map: HashMap<FaceId, FaceId> = HashMap::new();
        let mut new_faces = Vec::with_capacity(faces.len());
        for &f in &faces {
            let face = self.faces.get(f.0).ok_or_else(|| missing("face", f.0))?;
            let loops = face
                .loops
                .iter()
                .map(|l| Loop {
                    outer: l.outer,
                    coedges: l
                        .coedges
                        .iter()
                        .map(|c| Coedge {
                            edge: edge_map[&c.edge],
                            forward: c.forward,
                            pcurve: c.pcurve.clone(),
                            pcurve_deviation: c.pcurve_deviation.map(|d| d * grow),
                        })
                        .collect(),
                })
                .collect();
            // The vertices of its vertex loops, copied as the edges' are.
            let vertex_loops = face
                .vertex_loops
                .iter()
                .map(|&v| vertices.copy(self, v, placement, grow))
                .collect::<Result<Vec<_>, _>>()?;
            face_map.insert(f, FaceId(target.faces.len() + new_faces.len()));
            new_faces.push(Face {
                surface: face.surface.transform(placement).map_err(geometry)?,
                loops,
                same_sense: face.same_sense,
                vertex_loops,
            });
            copied.faces.push(f);
        }
        let mut shell_map: HashMap<ShellId, ShellId> = HashMap::new();
        let mut new_shells = Vec::with_capacity(shells.len());
        for &s in &shells {
            let shell = self.shells.get(s.0).ok_or_else(|| missing("shell", s.0))?;
            shell_map.insert(s, ShellId(target.shells.len() + new_shells.len()));
            new_shells.push(Shell {
                faces: shell
                    .faces
                    .iter()
                    .map(|&(f, o)| (face_map[&f], o))
                    .collect(),
                closed: shell.closed,
            });
            copied.shells.push(s);
        }
        let placed = match part {
            Part::Solid(s) => {
                copied.solids.push(s);
                Part::Solid(SolidId(target.solids.len()))
            }
            Part::Shell(s) => Part::Shell(shell_map[&s]),
            Part::Face(f) => Part::Face(face_map[&f]),
            Part::Edge(e) => Part::Edge(edge_map[&e]),
            Part::Assembly(a) => return Err(missing("part (an assembly)", a.0)),
        };
        target.vertices.extend(vertices.new);
        copied.vertices = vertices.sources;
        target.edges.extend(new_edges);
        target.faces.extend(new_faces);
        target.shells.extend(new_shells);
        if let Part::Solid(s) = part {
            let solid = &self.solids[s.0];
            target.solids.push(Solid {
                outer: shell_map[&solid.outer],
                voids: solid.voids.iter().map(|v| shell_map[v]).collect(),
            });
        }
        Ok((placed, copied))
    }
}

/// The vertices [`Model::place`] copies, each once however many edges and vertex loops use
/// it: source -> copy (numbered from `base`, the target's vertex count), the copies, and
/// their sources in the same order.
struct VertexCopies {
    base: usize,
    map: HashMap<VertexId, VertexId>,
    new: Vec<Vertex>,
    sources: Vec<VertexId>,
}

impl VertexCopies {
    /// The copy of `v` of `source`, placed by `placement` with its tolerance grown by
    /// `grow`; made on first use.
    fn copy(
        &mut self,
        source: &Model,
        v: VertexId,
        placement: &Affine,
        grow: f64,
    ) -> Result<VertexId, TopologyError> {
        if let Some(&id) = self.map.get(&v) {
            return Ok(id);
        }
        let vertex = source.vertices.get(v.0).ok_or(TopologyError::Missing {
            what: "vertex",
            index: v.0,
        })?;
        let id = VertexId(self.base + self.new.len());
        self.new.push(Vertex {
            point: apply(placement, vertex.point),
            tolerance: vertex.tolerance * grow,
        });
        self.sources.push(v);
        self.map.insert(v, id);
        Ok(id)
    }
}
