//! [`Document`] with a boundary representation -> STEP (ISO 10303-42 clauses 5 and 6, as
//! Open CASCADE writes parts, spec.md c.5):
//! - every vertex once (VERTEX_POINT), every edge once (EDGE_CURVE over its
//!   B_SPLINE_CURVE_WITH_KNOTS, which the vertices bound, running from its start to its end
//!   vertex, `same_sense` `.T.`), shared by the ORIENTED_EDGEs of the faces that use it;
//! - faces as ADVANCED_FACE over their B_SPLINE_SURFACE_WITH_KNOTS (rational: the complex
//!   instance), bounds as FACE_OUTER_BOUND / FACE_BOUND of EDGE_LOOPs, and a FACE_BOUND of
//!   a VERTEX_LOOP for each vertex loop;
//! - shells bounding solids as CLOSED_SHELL in MANIFOLD_SOLID_BREP (BREP_WITH_VOIDS with
//!   ORIENTED_CLOSED_SHELL voids), the other shells and the faces in no shell as
//!   OPEN_SHELL / CLOSED_SHELL in one SHELL_BASED_SURFACE_MODEL;
//! - the representation: ADVANCED_BREP_SHAPE_REPRESENTATION for solids only,
//!   MANIFOLD_SURFACE_SHAPE_REPRESENTATION for surface models only, else a
//!   SHAPE_REPRESENTATION holding all of them and the GEOMETRIC_SET of the free geometry
//!   (the entities no face or edge names, and the curves of edges in no face).
//!
//! An assembly's product structure is written over the same pieces (write/assembly.rs):
//! [`write_model`] writes the items of the parts once, each product's representation names
//! its own.
//!
//! An edge with parameter-space curves is written as a SURFACE_CURVE (SEAM_CURVE for the two
//! sides of a seam) over its 3-D curve with one PCURVE per face that knows one, as Open
//! CASCADE writes them; the 3-D curve stays the master representation (`.CURVE_3D.`).

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

use nurbsx_parsers::real::NonFiniteReal;
use nurbsx_parsers::step::writer::write_instance;
use nurbsx_parsers::step::{Body, Instance, Parameter, Record};

use super::{
    assemble, finish, geometric_set, real_error, s, write_curve, write_point, write_surface,
};
use crate::exchange::{Diagnostic, Document, Entity, ExportOptions, Meta, Origin, Origins, Source};
use crate::nurbs::{Geometry, NurbsCurve};
use crate::topology::{Model, ShellId};

/// Writes one simple instance `#id = KEYWORD(params);`.
fn put(
    out: &mut String,
    id: u64,
    keyword: &'static str,
    params: Vec<Parameter<'static>>,
) -> Result<(), NonFiniteReal> {
    write_instance(
        out,
        &Instance {
            id,
            body: Body::Simple(Record { keyword, params }),
        },
    )
}

fn boolean(b: bool) -> Parameter<'static> {
    Parameter::Enumeration(if b { "T" } else { "F" })
}

/// The entities of the document by id.
fn entities(document: &Document) -> HashMap<&str, &Entity> {
    document
        .entities
        .iter()
        .map(|e| (e.id.as_str(), e))
        .collect()
}

/// An entity standing for geometry that no document entity holds (metadata defaults).
fn anonymous(geometry: Geometry) -> Entity {
    Entity {
        id: Default::default(),
        geometry,
        source: Source::default(),
        meta: Meta::default(),
    }
}

/// The document entity an item's origin names when it holds the same geometry (its
/// metadata: name, form), else an anonymous one made by `make`.
fn held<'e>(
    origin: Option<&Origin>,
    by_id: &HashMap<&str, &'e Entity>,
    same: impl Fn(&Geometry) -> bool,
    make: impl FnOnce() -> Geometry,
) -> Cow<'e, Entity> {
    match origin
        .and_then(|x| x.entity.as_deref())
        .and_then(|x| by_id.get(x))
    {
        Some(e) if same(&e.geometry) => Cow::Borrowed(*e),
        _ => Cow::Owned(anonymous(make())),
    }
}

/// The writer's running state: the text of the topology instances and the next id.
pub(super) struct Out {
    pub text: String,
    pub id: u64,
}

impl Out {
    fn next(&mut self) -> u64 {
        let id = self.id;
        self.id += 1;
        id
    }

    pub fn put(
        &mut self,
        keyword: &'static str,
        params: Vec<Parameter<'static>>,
    ) -> Result<u64, NonFiniteReal> {
        let id = self.next();
        put(&mut self.text, id, keyword, params)?;
        Ok(id)
    }
}

/// The ids [`write_model`] gave a model's items.
pub(super) struct Written {
    /// Per solid: its MANIFOLD_SOLID_BREP or BREP_WITH_VOIDS.
    pub solids: Vec<Option<u64>>,
    /// Per shell: its CLOSED_SHELL or OPEN_SHELL (`None`: not written, each face in a
    /// solid's shell already).
    pub shells: Vec<Option<u64>>,
    /// Whether each shell bounds a solid.
    pub of_solid: Vec<bool>,
    /// Per face: its ADVANCED_FACE.
    pub faces: Vec<u64>,
    /// Whether each face is in a written shell.
    pub in_shell: Vec<bool>,
    /// Per edge: its 3-D B-spline curve.
    pub curves: Vec<u64>,
    /// Whether each edge bounds a face.
    pub in_face: Vec<bool>,
}

/// The ids of the free geometry [`write_free`] wrote.
pub(super) struct Free {
    /// 3-D curves.
    pub curves3: Vec<u64>,
    /// 2-D curves.
    pub curves2: Vec<u64>,
    /// Surfaces.
    pub surfaces: Vec<u64>,
}

/// Writes the free geometry of a document: the entities no item of `o` (the provenance of
/// `m`'s items) names, and not the 2-D curves the edges carry as pcurves.
pub(super) fn write_free(
    w: &mut Out,
    document: &Document,
    m: &Model,
    o: &Origins,
    scale: f64,
    options: &ExportOptions,
) -> Result<Free, NonFiniteReal> {
    let named = o.entity_ids();
    // The 2-D curves of the source's pcurves of edges whose every coedge carries a pcurve
    // (the reader's rule for not converting them): the edges carry their own. An edge of a
    // face the reader refused, or of none, carries none, and its file curves are written.
    let mut carried = vec![(false, true); m.edges.len()];
    for c in m
        .faces
        .iter()
        .flat_map(|f| &f.loops)
        .flat_map(|l| &l.coedges)
    {
        if let Some(x) = carried.get_mut(c.edge.0) {
            *x = (true, x.1 && c.pcurve.is_some());
        }
    }
    let edge_ids: HashSet<&str> = o
        .edges
        .iter()
        .zip(&carried)
        .filter(|(_, c)| c.0 && c.1)
        .map(|(x, _)| x.id.as_str())
        .collect();
    let is_pcurve = |e: &Entity| {
        matches!(&e.geometry, Geometry::Curve(c) if c.dimension() == 2)
            && e.meta.used_by.iter().any(|u| edge_ids.contains(u.as_str()))
    };
    let (mut curves3, mut curves2, mut surfaces) = (Vec::new(), Vec::new(), Vec::new());
    for e in &document.entities {
        if named.contains(e.id.as_str()) || is_pcurve(e) {
            continue;
        }
        match &e.geometry {
            Geometry::Curve(c) => {
                write_curve(&mut w.text, &mut w.id, c, e, scale, options)?;
                if c.dimension() == 2 {
                    curves2.push(w.id - 1);
                } else {
                    curves3.push(w.id - 1);
                }
            }
            Geometry::Surface(sf) => {
                write_surface(&mut w.text, &mut w.id, sf, e, scale, options)?;
                surfaces.push(w.id - 1);
            }
        }
    }
    Ok(Free {
        curves3,
        curves2,
        surfaces,
    })
}

/// Writes `document` (whose topology is not empty): its product structure when it has one
/// and the options do not ask for it flattened (`write/assembly.rs`), else its flattened
/// model as one product. Returns the text and what the assembly plan it followed says
/// (the diagnostics of [`assembly_warnings`](super::assembly_warnings)).
pub(super) fn write(
    document: &Document,
    options: &ExportOptions,
) -> Result<(String, Vec<Diagnostic>), Diagnostic> {
    let plan = super::assembly::plan(document, options);
    if let Some(structure) = &plan.structure {
        let text = super::assembly::write(document, options, structure)?;
        return Ok((text, plan.diagnostics));
    }
    let mut f = super::frame(document, options, None);
    let first = f.b.next_id();
    let scale = f.scale;
    let topo = &document.topology;
    let m = &topo.model;
    let mut w = Out {
        text: String::new(),
        id: first,
    };
    let body = (|| -> Result<_, NonFiniteReal> {
        // Free geometry first, as the geometry-only writer orders it.
        let Free {
            mut curves3,
            curves2,
            surfaces,
        } = write_free(&mut w, document, m, &topo.origins, scale, options)?;
        let written = write_model(&mut w, document, m, &topo.origins, scale, options)?;
        // The curves of edges in no face (one a curve several of them share).
        let mut listed = std::collections::HashSet::new();
        for (k, curve) in written.curves.iter().enumerate() {
            if !written.in_face[k] && listed.insert(*curve) {
                curves3.push(*curve);
            }
        }
        let mut top: Vec<(&'static str, u64)> = written
            .solids
            .iter()
            .flatten()
            .map(|id| ("solid", *id))
            .collect();
        let loose_shells: Vec<u64> = written
            .shells
            .iter()
            .zip(&written.of_solid)
            .filter(|(_, of_solid)| !**of_solid)
            .filter_map(|(id, _)| *id)
            .collect();
        let loose_faces: Vec<u64> = written
            .faces
            .iter()
            .zip(&written.in_shell)
            .filter(|(_, inside)| !**inside)
            .map(|(f, _)| *f)
            .collect();
        surface_model(&mut w, loose_shells, &loose_faces, &mut top)?;
        Ok((top, curves3, curves2, surfaces))
    })();
    let (body, curves3, curves2, surfaces) = body.map_err(real_error)?;
    f.b.reserve_many(w.id - first);
    let (set, set_keyword) = geometric_set(&mut f.b, &curves3, &surfaces);
    let rep_keyword = representation(&body, set.is_some(), set_keyword);
    let mut items: Vec<u64> = body.iter().map(|(_, id)| *id).collect();
    items.extend(set);
    let header = finish(&mut f, options, rep_keyword, &items, &curves2);
    let size = w.text.len() + 4096;
    let text = assemble(&mut f, &header, first, size, |out| {
        out.push_str(&w.text);
        Ok(())
    })?;
    Ok((text, plan.diagnostics))
}

/// Appends to `items` the SHELL_BASED_SURFACE_MODEL of `shells` and of one OPEN_SHELL of
/// `faces`, if there are any.
pub(super) fn surface_model(
    w: &mut Out,
    mut shells: Vec<u64>,
    faces: &[u64],
    items: &mut Vec<(&'static str, u64)>,
) -> Result<(), NonFiniteReal> {
    if !faces.is_empty() {
        shells.push(w.put("OPEN_SHELL", vec![s(""), Parameter::refs(faces)])?);
    }
    if !shells.is_empty() {
        items.push((
            "surface",
            w.put(
                "SHELL_BASED_SURFACE_MODEL",
                vec![s(""), Parameter::refs(&shells)],
            )?,
        ));
    }
    Ok(())
}

/// The representation that holds `items` (solids, surface models) and maybe a set of free
/// geometry (`set_keyword` the representation for the set alone).
pub(super) fn representation(
    items: &[(&'static str, u64)],
    set: bool,
    set_keyword: &'static str,
) -> &'static str {
    let solids = items.iter().any(|(k, _)| *k == "solid");
    let surface_models = items.iter().any(|(k, _)| *k == "surface");
    match (solids, surface_models, set) {
        (true, false, false) => "ADVANCED_BREP_SHAPE_REPRESENTATION",
        (false, true, false) => "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
        (false, false, _) => set_keyword,
        _ => "SHAPE_REPRESENTATION",
    }
}

/// Writes the vertices, edges, faces, shells and solids of `m` (provenance `o`, the
/// metadata of the document's entities they name) and returns their ids.
pub(super) fn write_model(
    w: &mut Out,
    document: &Document,
    m: &Model,
    o: &Origins,
    scale: f64,
    options: &ExportOptions,
) -> Result<Written, NonFiniteReal> {
    let by_id = entities(document);
    let mut vertex_ids = Vec::with_capacity(m.vertices.len());
    for v in &m.vertices {
        let p = w.next();
        write_point(&mut w.text, p, &v.point, 3, scale)?;
        vertex_ids.push(w.put("VERTEX_POINT", vec![s(""), Parameter::Reference(p)])?);
    }
    // Face surfaces before the edges: the edges' pcurves name them. A surface several
    // faces share (they name one entity and each carries its geometry bit for bit) is
    // written once, as read.
    let mut surface_ids = Vec::with_capacity(m.faces.len());
    let mut shared: HashMap<&str, u64> = HashMap::new();
    for (k, face) in m.faces.iter().enumerate() {
        let entity = held(
            o.faces.get(k),
            &by_id,
            |g| matches!(g, Geometry::Surface(x) if *x == face.surface),
            || Geometry::Surface(face.surface.clone()),
        );
        let label = match &entity {
            Cow::Borrowed(_) => o.faces.get(k).and_then(|x| x.entity.as_deref()),
            Cow::Owned(_) => None,
        };
        if let Some(&id) = label.and_then(|l| shared.get(l)) {
            surface_ids.push(id);
            continue;
        }
        write_surface(
            &mut w.text,
            &mut w.id,
            &face.surface,
            &entity,
            scale,
            options,
        )?;
        surface_ids.push(w.id - 1);
        if let Some(l) = label {
            shared.insert(l, w.id - 1);
        }
    }
    // The pcurves of each edge: (surface, pcurve, coedge runs with the edge, face), the
    // coedge running with the edge first (a seam's two sides, ISO 10303-42 seam_curve).
    let mut pcurves: Vec<Vec<(u64, &NurbsCurve, bool, usize)>> = vec![Vec::new(); m.edges.len()];
    for (k, face) in m.faces.iter().enumerate() {
        for l in &face.loops {
            for c in &l.coedges {
                if let (Some(p), Some(list)) = (&c.pcurve, pcurves.get_mut(c.edge.0)) {
                    list.push((surface_ids[k], p, c.forward, k));
                }
            }
        }
    }
    for list in &mut pcurves {
        list.sort_by_key(|(_, _, forward, _)| !forward);
    }
    let context2 = if pcurves.iter().any(|l| !l.is_empty()) {
        let id = w.next();
        write_instance(
            &mut w.text,
            &Instance {
                id,
                body: Body::Complex(vec![
                    Record {
                        keyword: "GEOMETRIC_REPRESENTATION_CONTEXT",
                        params: vec![Parameter::Integer(2)],
                    },
                    Record {
                        keyword: "PARAMETRIC_REPRESENTATION_CONTEXT",
                        params: vec![],
                    },
                    Record {
                        keyword: "REPRESENTATION_CONTEXT",
                        params: vec![s("2D SPACE"), s("")],
                    },
                ]),
            },
        )?;
        id
    } else {
        0
    };
    let mut in_face = vec![false; m.edges.len()];
    for face in &m.faces {
        for l in &face.loops {
            for c in &l.coedges {
                if let Some(x) = in_face.get_mut(c.edge.0) {
                    *x = true;
                }
            }
        }
    }
    let mut edge_ids = Vec::with_capacity(m.edges.len());
    let mut curve_ids = Vec::with_capacity(m.edges.len());
    // A curve several edges share (they name one entity and each carries its geometry bit
    // for bit: a B-spline several edges use, or the halves of an edge the reader split at
    // a seam) is written once, as read, each edge bounded by its own vertices.
    let mut shared_curves: HashMap<&str, u64> = HashMap::new();
    for (k, e) in m.edges.iter().enumerate() {
        // The whole curve: the edge's vertices bound it (ISO 10303-42 edge_curve), as
        // the files write a B-spline edge that uses part of its curve.
        let piece = &e.curve;
        let entity = held(
            o.edges.get(k),
            &by_id,
            |g| matches!(g, Geometry::Curve(x) if x == piece),
            || Geometry::Curve(piece.clone()),
        );
        let label = match &entity {
            Cow::Borrowed(_) => o.edges.get(k).and_then(|x| x.entity.as_deref()),
            Cow::Owned(_) => None,
        };
        let mut curve = match label.and_then(|l| shared_curves.get(l)) {
            Some(&id) => id,
            None => {
                write_curve(&mut w.text, &mut w.id, piece, &entity, scale, options)?;
                if let Some(l) = label {
                    shared_curves.insert(l, w.id - 1);
                }
                w.id - 1
            }
        };
        curve_ids.push(curve);
        // With pcurves: a SURFACE_CURVE (SEAM_CURVE when one face uses it twice, its two
        // pcurves then on that face's surface) over
        // the 3-D curve, each PCURVE a 2-D B-spline in the surface's (u, v) (not scaled:
        // parameters have no unit) in a DEFINITIONAL_REPRESENTATION.
        let on = &pcurves[k];
        if !on.is_empty() {
            let mut refs = Vec::with_capacity(on.len());
            for &(surface, p, _, _) in on {
                let holder = anonymous(Geometry::Curve(p.clone()));
                write_curve(&mut w.text, &mut w.id, p, &holder, 1.0, options)?;
                let c2 = w.id - 1;
                let rep = w.put(
                    "DEFINITIONAL_REPRESENTATION",
                    vec![
                        s(""),
                        Parameter::refs(&[c2]),
                        Parameter::Reference(context2),
                    ],
                )?;
                refs.push(w.put(
                    "PCURVE",
                    vec![
                        s(""),
                        Parameter::Reference(surface),
                        Parameter::Reference(rep),
                    ],
                )?);
            }
            let seam = on.len() == 2 && on[0].3 == on[1].3;
            curve = w.put(
                if seam { "SEAM_CURVE" } else { "SURFACE_CURVE" },
                vec![
                    s(""),
                    Parameter::Reference(curve),
                    Parameter::refs(&refs),
                    Parameter::Enumeration("CURVE_3D"),
                ],
            )?;
        }
        let (Some(&vs), Some(&ve)) = (vertex_ids.get(e.start.0), vertex_ids.get(e.end.0)) else {
            edge_ids.push(None);
            continue;
        };
        edge_ids.push(Some(w.put(
            "EDGE_CURVE",
            vec![
                s(""),
                Parameter::Reference(vs),
                Parameter::Reference(ve),
                Parameter::Reference(curve),
                boolean(true),
            ],
        )?));
    }
    // Which shells are written: those of solids, and the others unless each of their
    // faces is in a solid's shell already (the closed shell an oriented void was built
    // from).
    let mut of_solids: HashSet<ShellId> = HashSet::new();
    for solid in &m.solids {
        of_solids.insert(solid.outer);
        of_solids.extend(solid.voids.iter().copied());
    }
    let solid_faces: HashSet<usize> = of_solids
        .iter()
        .filter_map(|sh| m.shells.get(sh.0))
        .flat_map(|sh| sh.faces.iter().map(|(f, _)| f.0))
        .collect();
    let written = |k: usize, sh: &crate::topology::Shell| {
        of_solids.contains(&ShellId(k)) || !sh.faces.iter().all(|(f, _)| solid_faces.contains(&f.0))
    };
    // A face that every written shell uses reversed is written reversed (the other
    // side of `same_sense` and every bound's orientation flipped, ISO 10303-42
    // advanced_face / face_bound), so no ORIENTED_FACE is needed: Open CASCADE drops
    // ORIENTED_FACEs in a closed shell. A face used both ways keeps ORIENTED_FACE.
    let mut uses: Vec<(bool, bool)> = vec![(false, false); m.faces.len()];
    for (k, sh) in m.shells.iter().enumerate() {
        if !written(k, sh) {
            continue;
        }
        for &(f, same) in &sh.faces {
            if let Some(u) = uses.get_mut(f.0) {
                if same {
                    u.0 = true;
                } else {
                    u.1 = true;
                }
            }
        }
    }
    let reversed: Vec<bool> = uses.iter().map(|&(fwd, rev)| rev && !fwd).collect();
    let mut face_ids = Vec::with_capacity(m.faces.len());
    for (k, face) in m.faces.iter().enumerate() {
        let surface = surface_ids[k];
        let mut bounds = Vec::with_capacity(face.loops.len());
        for l in &face.loops {
            let mut oriented = Vec::with_capacity(l.coedges.len());
            for c in &l.coedges {
                let Some(Some(edge)) = edge_ids.get(c.edge.0) else {
                    continue;
                };
                oriented.push(w.put(
                    "ORIENTED_EDGE",
                    vec![
                        s(""),
                        Parameter::Derived,
                        Parameter::Derived,
                        Parameter::Reference(*edge),
                        boolean(c.forward),
                    ],
                )?);
            }
            let lp = w.put("EDGE_LOOP", vec![s(""), Parameter::refs(&oriented)])?;
            bounds.push(w.put(
                if l.outer {
                    "FACE_OUTER_BOUND"
                } else {
                    "FACE_BOUND"
                },
                vec![s(""), Parameter::Reference(lp), boolean(!reversed[k])],
            )?);
        }
        // Its vertex loops (a cone's apex, a sphere's pole: ISO 10303-42 vertex_loop).
        for v in &face.vertex_loops {
            let Some(&vertex) = vertex_ids.get(v.0) else {
                continue;
            };
            let lp = w.put("VERTEX_LOOP", vec![s(""), Parameter::Reference(vertex)])?;
            bounds.push(w.put(
                "FACE_BOUND",
                vec![s(""), Parameter::Reference(lp), boolean(true)],
            )?);
        }
        face_ids.push(w.put(
            "ADVANCED_FACE",
            vec![
                s(""),
                Parameter::refs(&bounds),
                Parameter::Reference(surface),
                boolean(face.same_sense != reversed[k]),
            ],
        )?);
    }
    let mut shell_ids: Vec<Option<u64>> = vec![None; m.shells.len()];
    let mut in_shell = vec![false; m.faces.len()];
    for (k, sh) in m.shells.iter().enumerate() {
        if !written(k, sh) {
            continue;
        }
        let mut refs = Vec::with_capacity(sh.faces.len());
        for &(f, same) in &sh.faces {
            let Some(&fid) = face_ids.get(f.0) else {
                continue;
            };
            if let Some(x) = in_shell.get_mut(f.0) {
                *x = true;
            }
            refs.push(if same != reversed[f.0] {
                fid
            } else {
                w.put(
                    "ORIENTED_FACE",
                    vec![
                        s(""),
                        Parameter::Derived,
                        Parameter::Reference(fid),
                        boolean(false),
                    ],
                )?
            });
        }
        let id = w.put(
            if sh.closed {
                "CLOSED_SHELL"
            } else {
                "OPEN_SHELL"
            },
            vec![s(""), Parameter::refs(&refs)],
        )?;
        shell_ids[k] = Some(id);
    }
    let mut solid_ids = Vec::with_capacity(m.solids.len());
    for solid in &m.solids {
        let Some(Some(outer)) = shell_ids.get(solid.outer.0) else {
            solid_ids.push(None);
            continue;
        };
        if solid.voids.is_empty() {
            solid_ids.push(Some(w.put(
                "MANIFOLD_SOLID_BREP",
                vec![s(""), Parameter::Reference(*outer)],
            )?));
        } else {
            let mut voids = Vec::with_capacity(solid.voids.len());
            for v in &solid.voids {
                if let Some(Some(shell)) = shell_ids.get(v.0) {
                    voids.push(w.put(
                        "ORIENTED_CLOSED_SHELL",
                        vec![
                            s(""),
                            Parameter::Derived,
                            Parameter::Reference(*shell),
                            boolean(true),
                        ],
                    )?);
                }
            }
            solid_ids.push(Some(w.put(
                "BREP_WITH_VOIDS",
                vec![s(""), Parameter::Reference(*outer), Parameter::refs(&voids)],
            )?));
        }
    }
    Ok(Written {
        solids: solid_ids,
        of_solid: (0..m.shells.len())
            .map(|k| of_solids.contains(&ShellId(k)))
            .collect(),
        shells: shell_ids,
        faces: face_ids,
        in_shell,
        curves: curve_ids,
        in_face,
    })
}
