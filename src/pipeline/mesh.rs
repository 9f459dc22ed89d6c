//! Tessellation output: which entities go into a mesh file, the welded triangle mesh of each
//! surface, and the writers (Wavefront OBJ, binary STL, binary glTF 2.0, and the SVG picture
//! of [`super::picture`]).
//!
//! A document with faces (its topology) is drawn as a part: each face trimmed by its loops
//! ([`crate::topology::Model::mesh`]: edges tessellated once and shared by their faces, so a
//! closed shell is watertight), named by the face's id, each edge as a line named by the
//! edge's id, then the free curves and surfaces (those no face or edge names). The surfaces
//! of faces and the curves of edges are not drawn a second time untrimmed.
//!
//! A surface's tessellation is a parameter grid; on a closed surface the grid's first and
//! last rows (the seam) and every vertex of a degenerate row (a pole) lie at the same point.
//! [`weld`] merges vertices that coincide within 1e-9 of the surface's size and drops the
//! triangles that welding leaves with a repeated vertex, so the mesh of a closed surface is
//! watertight (every edge shared by two triangles) with no zero-area triangle.

use std::io::Write as _;

use crate::exchange::{Diagnostic, Document, Entity, Location, Topology};
use crate::nurbs::tessellate::{Mesh, Polyline};
use crate::nurbs::vector::{cross, norm};
use crate::nurbs::{Geometry, Point3};
use crate::topology::{EdgeId, FaceId};

use super::ops::id_list;
use super::{ErrorKind, MeshFormat, PipelineError, Settings, select};

/// A welded triangle mesh of one surface.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaceMesh {
    /// The entity id (`#17`, `D5`).
    pub entity: String,
    /// Distinct vertex positions.
    pub positions: Vec<Point3>,
    /// Triangles as indices into `positions`, counter-clockwise seen from `S_u x S_v`.
    pub triangles: Vec<[u32; 3]>,
}

/// A tessellated curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveLine {
    /// The entity id.
    pub entity: String,
    /// Its points.
    pub points: Vec<Point3>,
}

/// What a mesh file will hold, and what it leaves out (with the warnings that say so).
#[derive(Debug)]
pub struct MeshPlan<'d> {
    /// The free entities to tessellate (those no face or edge names).
    pub entities: Vec<&'d Entity>,
    /// The document's topology when faces or edges are drawn.
    pub topology: Option<&'d Topology>,
    /// The faces to mesh, trimmed (indices into the topology's faces).
    pub faces: Vec<FaceId>,
    /// The edges to draw as lines (indices into the topology's edges).
    pub edges: Vec<usize>,
    /// One warning per kind of entity left out.
    pub left_out: Vec<Diagnostic>,
}

impl MeshPlan<'_> {
    /// How many items (entities, faces, edges) the mesh will hold.
    pub fn items(&self) -> usize {
        self.entities.len() + self.faces.len() + self.edges.len()
    }
}

/// Chooses the entities of a mesh file: the one asked for, or all. 2-D curves are left out
/// when 3-D geometry is drawn too (they are parameter-space curves of a B-rep, not geometry
/// in the plane z = 0); a file of 2-D curves only is drawn in that plane. STL holds
/// triangles only, so curves are left out of it.
///
/// With topology, all faces and edges are drawn, and `entity` may name one face (drawn
/// trimmed, with its edges) or one edge, as well as a free entity.
pub fn plan<'d>(
    doc: &'d Document,
    entity: Option<&str>,
    format: MeshFormat,
) -> Result<MeshPlan<'d>, PipelineError> {
    let topology = &doc.topology;
    let origins = &topology.origins;
    let (mut faces, mut edges): (Vec<FaceId>, Vec<usize>) = (Vec::new(), Vec::new());
    let selected: Vec<&Entity> = match entity {
        Some(id) => {
            let face = origins.faces.iter().position(|o| o.id == id);
            let edge = origins.edges.iter().position(|o| o.id == id);
            match (face, edge) {
                (Some(f), _) if f < topology.model.faces.len() => {
                    faces.push(FaceId(f));
                    let mut used: Vec<usize> = topology.model.faces[f]
                        .loops
                        .iter()
                        .flat_map(|l| l.coedges.iter().map(|c| c.edge.0))
                        .collect();
                    used.sort_unstable();
                    used.dedup();
                    edges = used;
                    Vec::new()
                }
                (_, Some(e)) if e < topology.model.edges.len() => {
                    edges.push(e);
                    Vec::new()
                }
                _ => vec![select(doc, Some(id))?],
            }
        }
        None => {
            faces = (0..topology.model.faces.len()).map(FaceId).collect();
            edges = (0..topology.model.edges.len()).collect();
            // The geometry of faces and edges is drawn through them, trimmed.
            let named: std::collections::HashSet<&str> = origins
                .faces
                .iter()
                .chain(&origins.edges)
                .filter_map(|o| o.entity.as_deref())
                .collect();
            doc.entities
                .iter()
                .filter(|e| !named.contains(e.id.as_str()))
                .collect()
        }
    };
    if selected.is_empty() && faces.is_empty() && edges.is_empty() {
        select(doc, None)?;
    }
    let is_curve = |e: &Entity| matches!(e.geometry, Geometry::Curve(_));
    let any_3d = !(faces.is_empty() && edges.is_empty())
        || selected.iter().any(|e| e.geometry.dimension() == 3);
    let mut left_out = Vec::new();
    let mut warn = |dropped: &[&Entity], code: &str, why: &str| {
        if let Some(first) = dropped.first() {
            left_out.push(Diagnostic::warning(
                code,
                format!(
                    "{} curve(s) not drawn ({}): {why}",
                    dropped.len(),
                    id_list(dropped.iter().copied())
                ),
                Location::at_entity(first.id.clone()),
            ));
        }
    };
    let (pcurves, mut kept): (Vec<&Entity>, Vec<&Entity>) = selected
        .into_iter()
        .partition(|e| any_3d && is_curve(e) && e.geometry.dimension() == 2);
    warn(
        &pcurves,
        "pcurve_not_written",
        "2-D parameter-space curves have no place in a 3-D picture or mesh",
    );
    if format == MeshFormat::Stl {
        let (curves, surfaces): (Vec<&Entity>, Vec<&Entity>) =
            kept.into_iter().partition(|e| is_curve(e));
        warn(&curves, "curve_not_written", "STL holds triangles only");
        kept = surfaces;
        if let Some(&first) = edges.first() {
            left_out.push(Diagnostic::warning(
                "curve_not_written",
                format!(
                    "{} curve(s) not drawn (the part's edges): STL holds triangles only (the \
                     faces' triangles still meet along them)",
                    edges.len()
                ),
                Location::at_entity(
                    origins
                        .edges
                        .get(first)
                        .map_or_else(String::new, |o| o.id.to_string()),
                ),
            ));
            edges.clear();
        }
    }
    let drawn = !(faces.is_empty() && edges.is_empty());
    Ok(MeshPlan {
        entities: kept,
        topology: drawn.then_some(topology),
        faces,
        edges,
        left_out,
    })
}

/// Welds a surface tessellation: vertices within 1e-9 of the mesh's bounding-box diagonal
/// become one, and triangles left with a repeated vertex or no area are dropped. The
/// mesh's parameters and normals are dropped first (a welded mesh has positions and
/// triangles only); the search costs 44 bytes a vertex (see [`MESH_VERTEX_WORK_BYTES`]).
pub fn weld(entity: &str, mesh: Mesh) -> FaceMesh {
    let Mesh {
        vertices,
        triangles,
        ..
    } = mesh;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let eps = (1e-9 * diagonal).max(f64::MIN_POSITIVE);
    // Vertices are binned in cells of size eps; a vertex is merged into the first earlier
    // representative (a vertex that was not merged) within eps, searched in the 27 cells
    // around its own, each cell's representatives in the order they were found. The
    // vertices sorted by (cell, index) make each column of 3 cells along z one run of the
    // order, found by binary search; merged vertices are skipped through `skip` (a
    // union-find of the next unmerged position, with path halving), so a cell where many
    // vertices meet (a pole) costs no more than one with a single vertex.
    let cell = |p: &Point3| -> [i64; 3] {
        // In range: (p - lo) / eps <= 1e9 (the saturating cast guards the rest).
        [0, 1, 2].map(|k| ((p[k] - lo[k]) / eps).floor() as i64)
    };
    let index = |i: usize| u32::try_from(i).unwrap_or(u32::MAX);
    let mut order: Vec<([i64; 3], u32)> = vertices
        .iter()
        .enumerate()
        .map(|(i, p)| (cell(p), index(i)))
        .collect();
    order.sort_unstable();
    // Where each vertex is in `order`.
    let mut at = vec![0u32; order.len()];
    for (k, &(_, j)) in order.iter().enumerate() {
        at[j as usize] = index(k);
    }
    // skip[k] leads to the first position from k on whose vertex was not merged; the last
    // entry ends the order.
    let mut skip: Vec<u32> = (0..=order.len()).map(index).collect();
    let unmerged_from = |skip: &mut Vec<u32>, mut k: usize| -> usize {
        while skip[k] as usize != k {
            let next = skip[skip[k] as usize];
            skip[k] = next;
            k = next as usize;
        }
        k
    };
    let mut positions: Vec<Point3> = Vec::with_capacity(vertices.len());
    let mut remap: Vec<u32> = Vec::with_capacity(vertices.len());
    for (i, p) in vertices.iter().enumerate() {
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                let (x, y) = (c[0] + dx, c[1] + dy);
                let mut k = order.partition_point(|(key, _)| *key < [x, y, c[2] - 1]);
                loop {
                    k = unmerged_from(&mut skip, k);
                    let Some(&(key, j)) = order.get(k) else {
                        break;
                    };
                    if key[0] != x || key[1] != y || key[2] > c[2] + 1 {
                        break;
                    }
                    if j as usize >= i {
                        // The rest of this cell is not placed yet: on to the next cell.
                        k = order.partition_point(|(other, _)| *other <= key);
                        continue;
                    }
                    let w = remap[j as usize];
                    let q = positions[w as usize];
                    let d2: f64 = (0..3).map(|k| (p[k] - q[k]).powi(2)).sum();
                    if d2 <= eps * eps {
                        found = Some(w);
                        break 'search;
                    }
                    k += 1;
                }
            }
        }
        remap.push(match found {
            Some(w) => {
                let k = at[i] as usize;
                skip[k] = index(k + 1);
                w
            }
            None => {
                positions.push(*p);
                index(positions.len() - 1)
            }
        });
    }
    drop((order, at, skip, vertices));
    let mut kept = Vec::with_capacity(triangles.len());
    kept.extend(triangles.iter().map(|t| t.map(|v| remap[v])).filter(|t| {
        t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            norm(area_vector(a, b, c)) > 0.0
        }
    }));
    FaceMesh {
        entity: entity.to_owned(),
        positions,
        triangles: kept,
    }
}

/// Twice the area vector of a triangle: `(b - a) x (c - a)`.
fn area_vector(a: Point3, b: Point3, c: Point3) -> Point3 {
    cross(
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    )
}

/// The unit normal of a triangle (zero for a degenerate one).
pub fn triangle_normal(a: Point3, b: Point3, c: Point3) -> Point3 {
    let n = area_vector(a, b, c);
    let l = norm(n);
    if l > 0.0 {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// What [`tessellate_all`] made: the face meshes, the lines, and warnings about faces it
/// could not mesh.
#[derive(Debug, Clone, Default)]
pub struct Tessellation {
    /// Triangle meshes (trimmed faces, then free surfaces).
    pub faces: Vec<FaceMesh>,
    /// Lines (edges, then free curves).
    pub curves: Vec<CurveLine>,
    /// Faces left out (`tessellate.face_skipped`, one per face, located) and triangles that
    /// stayed above the tolerance (`tessellate.face_unrefined`).
    pub diagnostics: Vec<Diagnostic>,
}

/// Bytes of working memory a tessellation takes per vertex, at most, while it is built: a
/// surface's grid mesh holds 112 bytes a grid vertex (position 24, parameters 16, normal
/// 24, two triangles of `usize` indices 48), and before it the grid's points with the set
/// of cells that passed, up to about 140 while that set grows; its weld, 140 (the mesh
/// without parameters and normals, 72, the search's 44, the welded positions 24); a welded
/// mesh kept for the writer, 48; a curve, 32 a point. Meshes are built one at a time and
/// each counts against what the ones before it left of [`vertex_cap`], so the whole
/// tessellation stays within [`vertex_cap`] times this (the allocator's rounding is the
/// margin).
pub const MESH_VERTEX_WORK_BYTES: usize = 160;

/// The working-memory budget of a tessellation: 3 times [`Settings::max_reply_bytes`]
/// (the service's `--max-reply-bytes`; none in the CLI, whose reply limit is none).
pub fn mesh_memory_budget(settings: &Settings) -> usize {
    settings.max_reply_bytes.saturating_mul(3)
}

/// The most vertices a tessellation may build: [`Settings::max_mesh_vertices`], and its
/// working-memory budget at [`MESH_VERTEX_WORK_BYTES`] a vertex (checked against the
/// estimate before the work and enforced during it).
pub fn vertex_cap(settings: &Settings) -> usize {
    settings
        .max_mesh_vertices
        .min(mesh_memory_budget(settings) / MESH_VERTEX_WORK_BYTES)
}

/// The 413 of a tessellation (`what`: "the mesh of #12") that needs more vertices than
/// [`vertex_cap`] allows: `limit.mesh_memory` when the memory budget is the tighter bound,
/// else `limit.mesh_vertices`.
pub fn over_the_cap(what: &str, settings: &Settings) -> PipelineError {
    let cap = vertex_cap(settings);
    if cap < settings.max_mesh_vertices {
        PipelineError::new(
            ErrorKind::Limit,
            "limit.mesh_memory",
            format!(
                "{what} needs more than {cap} vertices, more than its working-memory budget \
                 of {} bytes allows at {MESH_VERTEX_WORK_BYTES} bytes a vertex (the budget is \
                 3 times the reply limit of {} bytes); use a larger tolerance or fewer entities",
                mesh_memory_budget(settings),
                settings.max_reply_bytes
            ),
            Location::default(),
        )
    } else {
        PipelineError::new(
            ErrorKind::Limit,
            "limit.mesh_vertices",
            format!(
                "{what} needs more vertices than remain of the limit of {} (all entities \
                 together); use a larger tolerance",
                settings.max_mesh_vertices
            ),
            Location::default(),
        )
    }
}

/// Tessellates the planned faces, edges and entities under a chord tolerance, within the
/// vertex limit.
pub fn tessellate_all(
    plan: &MeshPlan<'_>,
    tolerance: f64,
    settings: &Settings,
) -> Result<Tessellation, PipelineError> {
    use crate::nurbs::tessellate::{Budget, TessellationError};
    let stop = || settings.cancel.is_set();
    let cap = vertex_cap(settings);
    let over = |what: &str| over_the_cap(what, settings);
    let failed = |e: &Entity, err: TessellationError| match err {
        TessellationError::Geometry(g) => PipelineError::new(
            ErrorKind::Geometry,
            "tessellate.failed",
            g.to_string(),
            Location::at_entity(e.id.clone()),
        ),
        TessellationError::TooManyPoints { .. } => over(&format!("the mesh of {}", e.id)),
        TessellationError::Stopped => super::cancelled(),
    };
    // Each entity may use what the ones before it left of the vertex limit.
    let mut vertices = 0usize;
    let within = |used: usize| Budget {
        max_points: cap.saturating_sub(used),
        stop: &stop,
    };
    let mut faces = Vec::new();
    let mut curves = Vec::new();
    let mut diagnostics = Vec::new();
    if let Some(topology) = plan.topology {
        let origin = |list: &[crate::exchange::Origin], i: usize| {
            list.get(i)
                .map_or_else(|| format!("{i}"), |o| o.id.to_string())
        };
        // An edge's line is named by the curve entity that holds its geometry (which
        // `info` describes: kind, degree, poles, knots), else by the edge's own id.
        let edge_name = |i: usize| {
            topology.origins.edges.get(i).map_or_else(
                || format!("{i}"),
                |o| o.entity.as_ref().unwrap_or(&o.id).to_string(),
            )
        };
        let mut part = topology
            .model
            .mesh(Some(&plan.faces), tolerance, &within(0))
            .map_err(|err| match err {
                TessellationError::Geometry(g) => PipelineError::new(
                    ErrorKind::Geometry,
                    "tessellate.failed",
                    g.to_string(),
                    Location::default(),
                ),
                TessellationError::TooManyPoints { .. } => over("the meshes of the faces"),
                TessellationError::Stopped => super::cancelled(),
            })?;
        for &f in &plan.faces {
            if let Some(mesh) = part.faces.get_mut(f.0).and_then(Option::take) {
                vertices += mesh.vertices.len();
                faces.push(weld(&origin(&topology.origins.faces, f.0), mesh));
            }
        }
        for (f, why) in &part.skipped {
            diagnostics.push(Diagnostic::warning(
                "tessellate.face_skipped",
                format!(
                    "face {} not drawn: {why}",
                    origin(&topology.origins.faces, f.0)
                ),
                Location::at_entity(origin(&topology.origins.faces, f.0)),
            ));
        }
        if let Some(first) = part.against_same_sense.first() {
            diagnostics.push(Diagnostic::warning(
                "tessellate.face_orientation",
                format!(
                    "{} face(s) have loops that run against their same_sense flag; their \
                     triangles face the way the loops say",
                    part.against_same_sense.len()
                ),
                Location::at_entity(origin(&topology.origins.faces, first.0)),
            ));
        }
        if part.unrefined > 0 {
            diagnostics.push(Diagnostic::warning(
                "tessellate.face_unrefined",
                format!(
                    "{} triangle(s) of the faces are still farther than the tolerance {tolerance} \
                     from their surface after {} refinement rounds",
                    part.unrefined,
                    crate::topology::MAX_ROUNDS
                ),
                Location::default(),
            ));
        }
        for &e in &plan.edges {
            // The edges of the faces asked for were tessellated with them; others alone.
            let line = match part.edges.get(e) {
                Some(Some(line)) => line.clone(),
                _ => {
                    let entity = origin(&topology.origins.edges, e);
                    match topology
                        .model
                        .edge_polyline(EdgeId(e), tolerance, &within(vertices))
                    {
                        Ok(line) => line,
                        Err(TessellationError::Stopped) => return Err(super::cancelled()),
                        Err(TessellationError::Geometry(g)) => {
                            return Err(PipelineError::new(
                                ErrorKind::Geometry,
                                "tessellate.failed",
                                g.to_string(),
                                Location::at_entity(entity),
                            ));
                        }
                        Err(TessellationError::TooManyPoints { .. }) => {
                            return Err(over(&format!("the edge {entity}")));
                        }
                    }
                }
            };
            vertices += line.points.len();
            curves.push(CurveLine {
                entity: edge_name(e),
                points: line.points,
            });
        }
    }
    for e in &plan.entities {
        match &e.geometry {
            Geometry::Curve(c) => {
                let line: Polyline = c
                    .tessellate_within(tolerance, &within(vertices))
                    .map_err(|err| failed(e, err))?;
                vertices += line.points.len();
                curves.push(CurveLine {
                    entity: e.id.to_string(),
                    points: line.points,
                });
            }
            Geometry::Surface(s) => {
                let mesh = s
                    .tessellate_within(tolerance, &within(vertices))
                    .map_err(|err| failed(e, err))?;
                vertices += mesh.vertices.len();
                faces.push(weld(&e.id, mesh));
            }
        }
    }
    Ok(Tessellation {
        faces,
        curves,
        diagnostics,
    })
}

/// Wavefront OBJ: one `o` group per entity, welded `v`ertices, `f` triangles and `l` lines
/// (indices are 1-based and global), written as it is formatted.
pub fn write_obj(
    out: &mut dyn std::io::Write,
    faces: &[FaceMesh],
    curves: &[CurveLine],
) -> std::io::Result<()> {
    let out = &mut std::io::BufWriter::new(out);
    out.write_all(b"# nurbsx tessellation\n")?;
    let mut base = 1usize;
    for f in faces {
        writeln!(out, "o {}", f.entity)?;
        for p in &f.positions {
            writeln!(out, "v {} {} {}", p[0], p[1], p[2])?;
        }
        for t in &f.triangles {
            let [a, b, c] = t.map(|v| base + v as usize);
            writeln!(out, "f {a} {b} {c}")?;
        }
        base += f.positions.len();
    }
    for c in curves {
        writeln!(out, "o {}", c.entity)?;
        for p in &c.points {
            writeln!(out, "v {} {} {}", p[0], p[1], p[2])?;
        }
        out.write_all(b"l")?;
        for k in 0..c.points.len() {
            write!(out, " {}", base + k)?;
        }
        out.write_all(b"\n")?;
        base += c.points.len();
    }
    out.flush()
}

/// The size of [`write_stl`]'s file: 84 bytes and 50 per triangle.
pub fn stl_bytes(faces: &[FaceMesh]) -> usize {
    let count: usize = faces.iter().map(|f| f.triangles.len()).sum();
    count.saturating_mul(50).saturating_add(84)
}

/// Binary STL: an 80-byte header, the triangle count, then per triangle its unit normal,
/// three vertices (little-endian `f32`) and a zero attribute word.
pub fn write_stl(out: &mut dyn std::io::Write, faces: &[FaceMesh]) -> std::io::Result<()> {
    let out = &mut std::io::BufWriter::new(out);
    let count: usize = faces.iter().map(|f| f.triangles.len()).sum();
    let mut header = [b' '; 80];
    let title = b"nurbsx tessellation (binary STL)";
    header[..title.len()].copy_from_slice(title);
    out.write_all(&header)?;
    out.write_all(&u32::try_from(count).unwrap_or(u32::MAX).to_le_bytes())?;
    for f in faces {
        for t in &f.triangles {
            let [a, b, c] = t.map(|v| f.positions[v as usize]);
            for p in [triangle_normal(a, b, c), a, b, c] {
                for x in p {
                    out.write_all(&(x as f32).to_le_bytes())?;
                }
            }
            out.write_all(&0u16.to_le_bytes())?;
        }
    }
    out.flush()
}

/// Binary glTF 2.0 (`.glb`): one node and mesh per entity; surfaces as indexed triangles,
/// curves as line strips; positions `f32`, indices `u32`; every accessor with the
/// `min`/`max` the specification requires for positions. Laid out before it is written
/// ([`Glb::layout`]: the JSON chunk, and the BIN chunk's length from the mesh counts), so
/// that its size is known first and the BIN chunk is written from the mesh as it goes.
pub struct Glb {
    /// The JSON chunk, padded with spaces to a multiple of 4 bytes.
    json: Vec<u8>,
    /// The BIN chunk's data length (before its padding).
    bin: usize,
}

impl Glb {
    /// The JSON chunk and the BIN chunk's length of the mesh (glTF 2.0 section 4.4: one
    /// buffer; buffer views in the order [`Glb::write`] writes their data).
    pub fn layout(faces: &[FaceMesh], curves: &[CurveLine]) -> Glb {
        use serde_json::{Value, json};
        let mut bin = 0usize;
        let mut views = Vec::new();
        let mut accessors = Vec::new();
        let mut meshes = Vec::new();
        /// A vertex buffer view of `points` at `*bin` and its accessor; returns the accessor.
        fn positions(
            points: &[Point3],
            bin: &mut usize,
            views: &mut Vec<Value>,
            accessors: &mut Vec<Value>,
        ) -> usize {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in points {
                for k in 0..3 {
                    let x = p[k] as f32;
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
            }
            let length = points.len() * 12;
            views.push(
                json!({"buffer": 0, "byteOffset": *bin, "byteLength": length, "target": 34962}),
            );
            *bin += length;
            accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5126,
                "count": points.len(), "type": "VEC3", "min": lo, "max": hi}));
            accessors.len() - 1
        }
        for f in faces {
            let pos = positions(&f.positions, &mut bin, &mut views, &mut accessors);
            meshes.push(
                json!({"name": f.entity, "primitives": [{"attributes": {"POSITION": pos},
                "indices": accessors.len(), "mode": 4}]}),
            );
            let length = f.triangles.len() * 12;
            views.push(
                json!({"buffer": 0, "byteOffset": bin, "byteLength": length, "target": 34963}),
            );
            bin += length;
            accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5125,
                "count": 3 * f.triangles.len(), "type": "SCALAR"}));
        }
        for c in curves {
            let pos = positions(&c.points, &mut bin, &mut views, &mut accessors);
            meshes.push(
                json!({"name": c.entity, "primitives": [{"attributes": {"POSITION": pos}, "mode": 3}]}),
            );
        }
        let nodes: Vec<Value> = meshes
            .iter()
            .enumerate()
            .map(|(i, m)| json!({"mesh": i, "name": m["name"]}))
            .collect();
        let mut document = json!({
            "asset": {"version": "2.0", "generator": concat!("nurbsx ", env!("CARGO_PKG_VERSION"))},
            "scene": 0,
            "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
            "nodes": nodes,
            "meshes": meshes,
            "accessors": accessors,
            "bufferViews": views,
        });
        if bin > 0 {
            document["buffers"] = json!([{"byteLength": bin}]);
        }
        let mut json = document.to_string().into_bytes();
        // Chunks are 4-byte aligned: JSON padded with spaces, binary data with zeros.
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        Glb { json, bin }
    }

    /// The file's size in bytes: header, JSON chunk, BIN chunk (when not empty).
    pub fn size(&self) -> usize {
        12 + 8
            + self.json.len()
            + if self.bin == 0 {
                0
            } else {
                8 + self.bin.next_multiple_of(4)
            }
    }

    /// Writes the file laid out by [`Glb::layout`] of the same `faces` and `curves`: the
    /// header, the JSON chunk, then the BIN chunk from the mesh, face by face.
    pub fn write(
        &self,
        out: &mut dyn std::io::Write,
        faces: &[FaceMesh],
        curves: &[CurveLine],
    ) -> std::io::Result<()> {
        let u32_le = |n: usize| u32::try_from(n).unwrap_or(u32::MAX).to_le_bytes();
        let mut out = std::io::BufWriter::with_capacity(64 * 1024, out);
        out.write_all(b"glTF")?;
        out.write_all(&2u32.to_le_bytes())?;
        out.write_all(&u32_le(self.size()))?;
        out.write_all(&u32_le(self.json.len()))?;
        out.write_all(b"JSON")?;
        out.write_all(&self.json)?;
        if self.bin == 0 {
            return out.flush();
        }
        let padded = self.bin.next_multiple_of(4);
        out.write_all(&u32_le(padded))?;
        out.write_all(b"BIN\0")?;
        let points = |out: &mut dyn std::io::Write, points: &[Point3]| -> std::io::Result<()> {
            for x in points.iter().flatten() {
                out.write_all(&(*x as f32).to_le_bytes())?;
            }
            Ok(())
        };
        for f in faces {
            points(&mut out, &f.positions)?;
            for t in &f.triangles {
                for v in t {
                    out.write_all(&v.to_le_bytes())?;
                }
            }
        }
        for c in curves {
            points(&mut out, &c.points)?;
        }
        out.write_all(&[0; 3][..padded - self.bin])?;
        out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere's parameter grid (its first and last rows are the poles, its first and
    /// last columns the seam) welds as a brute-force search over all earlier distinct
    /// vertices does: the same positions in the same order, the same triangles, and
    /// 2 + (rows - 2) x (columns - 1) vertices.
    #[test]
    fn weld_merges_poles_and_seam_as_a_brute_force_search_does() {
        use std::f64::consts::PI;
        let (nu, nv) = (9usize, 13usize);
        let mut vertices = Vec::new();
        for i in 0..nu {
            let theta = PI * i as f64 / (nu - 1) as f64;
            for j in 0..nv {
                let phi = 2.0 * PI * j as f64 / (nv - 1) as f64;
                vertices.push([
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ]);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..nu - 1 {
            for j in 0..nv - 1 {
                let (a, b) = (i * nv + j, (i + 1) * nv + j);
                triangles.push([a, b, b + 1]);
                triangles.push([a, b + 1, a + 1]);
            }
        }
        // Distinct grid points are at least 0.03 apart; coinciding ones within 1e-15.
        let mut distinct: Vec<Point3> = Vec::new();
        let mut remap = Vec::new();
        for p in &vertices {
            let near = |q: &Point3| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>() < 1e-12;
            remap.push(distinct.iter().position(near).unwrap_or_else(|| {
                distinct.push(*p);
                distinct.len() - 1
            }) as u32);
        }
        let expected: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| remap[v]))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        let mesh = Mesh {
            vertices,
            triangles,
            ..Mesh::default()
        };
        let welded = weld("#1", mesh);
        assert_eq!(welded.positions.len(), 2 + (nu - 2) * (nv - 1));
        assert_eq!(welded.positions, distinct);
        assert_eq!(welded.triangles, expected);
    }
}
