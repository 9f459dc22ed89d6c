//! What a file holds, in one form for both formats.

use std::borrow::Cow;

use serde::Serialize;

/// A label of the model: an entity's or an item's id in its source file (`#17` in STEP,
/// `D5` in IGES) or a made-up one. Held inline up to 24 bytes (every file label), so that
/// the hundreds of thousands of a large read are no heap allocation each; reads as a `&str`.
pub type Label = compact_str::CompactString;

use super::{Diagnostic, Format, LengthUnit, Severity};
use crate::nurbs::{Geometry, Point3};
use crate::topology::{AssemblyId, Model};

/// A STEP or IGES file as nurbsx understands it: its B-spline entities (each with provenance
/// and format metadata), its declared length unit, and what the reader noticed.
///
/// Geometry coordinates are in [`Document::units`]: the file's own unit unless the import
/// options asked for another one (then the reader scaled and said so in a diagnostic).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Document {
    /// The format the document was read from (or will be written as).
    #[serde(serialize_with = "format_name")]
    pub format: Format,
    /// STEP: the FILE_SCHEMA identifier(s) joined by `, `; IGES: `IGES 5.3` etc. from the
    /// version flag.
    pub schema: Option<String>,
    /// The length unit the coordinates are in.
    pub units: LengthUnit,
    /// The curves and surfaces, in file order, each as exact NURBS: the free ones and, as
    /// today's geometry-level view, the surfaces of faces and the curves of edges too (each
    /// named by the [`Origin::entity`] of its face or edge in [`Document::topology`]).
    pub entities: Vec<Entity>,
    /// The boundary representation (faces with their loops, edges, vertices, shells,
    /// solids, assemblies) over the same exact geometry; empty when the file has none or
    /// when it was read geometry-only ([`ImportOptions::geometry_only`](super::ImportOptions)).
    /// Writers write it and then the entities that no face or edge names.
    #[serde(skip)]
    pub topology: Topology,
    /// Everything the reader noticed, in file order.
    pub diagnostics: Vec<Diagnostic>,
}

/// A file's boundary representation and where each piece of it came from.
///
/// `origins.faces[i]` describes `model.faces[i]`, and so on for every kind: readers push
/// both together, so the vectors stay index-aligned.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Topology {
    /// The checked topology over exact NURBS geometry.
    pub model: Model,
    /// Provenance of each vertex, edge, face, shell, solid and assembly of `model`.
    pub origins: Origins,
    /// The assembly tree the reader applied, depth first: every named instance (a STEP
    /// next_assembly_usage_occurrence or mapped_item, an IGES 408) with its placement. The
    /// items it placed are in `model` in root coordinates, their origin ids carrying the
    /// instance's path after `@` (`#41@Bracket_2`).
    pub instances: Vec<PlacedInstance>,
    /// The assembly as the file defines it, for writers that write a product structure
    /// (STEP): `None` unless the reader applied an assembly's placements. `model` above stays
    /// what geometry commands read; a command that rewrites `model` drops this too.
    pub structure: Option<Box<ProductStructure>>,
}

/// An assembly's parts and tree before placement (ISO 10303-44 product structure, IGES 5.3
/// 308/408 subfigures).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ProductStructure {
    /// Every part once, in its own coordinates, and in `model.assemblies` the tree: one
    /// assembly per product definition (or subfigure, or mapped representation), named by
    /// its product, whose instances name this model's solids, shells, faces and edges (the
    /// product's own shape, unnamed, under the identity) or other assemblies (named, placed).
    pub model: Model,
    /// Provenance of `model`'s items: the ids of the file, without the `@path` of the
    /// placed copies.
    pub origins: Origins,
    /// The assemblies no other one uses, in file order; the first also holds, unnamed under
    /// the identity, the items no product's shape holds.
    pub roots: Vec<AssemblyId>,
}

/// One placed use of a product (or subfigure) in an assembly.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacedInstance {
    /// The instance names from the root down, `/`-separated: what follows `@` in the ids
    /// of the items it placed.
    pub path: String,
    /// The file entity that places it: `#464` (a NEXT_ASSEMBLY_USAGE_OCCURRENCE), `#90` (a
    /// MAPPED_ITEM), `D45` (an IGES 408).
    pub id: String,
    /// The product (or subfigure) placed.
    pub product: String,
    /// Nesting level: 1 for an instance in a root assembly.
    pub depth: usize,
    /// Where it goes in its parent's coordinates: `x' = R x + T` as 3 rows `[r r r t]`.
    pub placement: [[f64; 4]; 3],
    /// Where it goes in root coordinates (the placements composed from the root down).
    pub world: [[f64; 4]; 3],
    /// The ids of the solids, shells, faces and free edges this instance itself placed (in
    /// `model`, root coordinates); those of its sub-instances are listed under them.
    pub places: Vec<String>,
}

impl Topology {
    /// Whether there is no topology at all.
    pub fn is_empty(&self) -> bool {
        let m = &self.model;
        m.vertices.is_empty()
            && m.edges.is_empty()
            && m.faces.is_empty()
            && m.shells.is_empty()
            && m.solids.is_empty()
            && m.assemblies.is_empty()
    }
}

/// Provenance of the items of a [`Model`], index-aligned with its vectors.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Origins {
    /// Of `model.vertices`.
    pub vertices: Vec<Origin>,
    /// Of `model.edges`.
    pub edges: Vec<Origin>,
    /// Of `model.faces`.
    pub faces: Vec<Origin>,
    /// Of `model.shells`.
    pub shells: Vec<Origin>,
    /// Of `model.solids`.
    pub solids: Vec<Origin>,
    /// Of `model.assemblies`.
    pub assemblies: Vec<Origin>,
}

impl Origins {
    /// The [`Entity::id`]s the topological items hold their geometry in (a face's surface,
    /// an edge's curve...).
    pub fn entity_ids(&self) -> std::collections::HashSet<&str> {
        [
            &self.vertices,
            &self.edges,
            &self.faces,
            &self.shells,
            &self.solids,
        ]
        .into_iter()
        .flatten()
        .filter_map(|x| x.entity.as_deref())
        .collect()
    }
}

/// Where one topological item came from.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Origin {
    /// The item's id in the source file: `#40` (an ADVANCED_FACE), `D45` (an IGES 144 or
    /// 510); for items made in memory, any unique label.
    pub id: Label,
    /// The source entity and line.
    pub source: Source,
    /// STEP `name`, IGES label (DE field 18) or 406 name property.
    pub name: Option<String>,
    /// The [`Entity::id`] in [`Document::entities`] holding this item's geometry (a face's
    /// surface, an edge's curve), whose [`Meta`] (shape, forms) writers use; `None` when
    /// the geometry is only in the topology.
    pub entity: Option<Label>,
}

/// Serialises a [`Format`] as `"step"` or `"iges"`.
fn format_name<S: serde::Serializer>(f: &Format, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(match f {
        Format::Step => "step",
        Format::Iges => "iges",
    })
}

impl Document {
    /// An empty document in the given format and unit.
    pub fn new(format: Format, units: LengthUnit) -> Self {
        Document {
            format,
            schema: None,
            units,
            entities: Vec::new(),
            topology: Topology::default(),
            diagnostics: Vec::new(),
        }
    }

    /// Makes the document list the surface each face in `faces` carries, for faces whose
    /// reader moved their surface's seam (exactly: the same surface with other poles and
    /// knots, [`crate::topology::moved_seams`], [`crate::topology::seam_splits`]).
    /// Writers write a face's surface, not its entity, so without this the document would
    /// list a surface it never writes, and a file read, written and read again would list
    /// another. Where no other face carries the surface as read, the face's entity becomes
    /// the moved surface. Where others do (a surface several faces share), the moved
    /// surface is listed beside it as an entity of its own, labelled `<surface>@<face>` as
    /// the readers label a curve several edges share, with the same source and metadata,
    /// and the face names it. Called by the readers before any placement moves the model.
    pub(crate) fn adopt_moved_surfaces(&mut self, faces: &[crate::topology::FaceId]) {
        if faces.is_empty() {
            return;
        }
        let moved: std::collections::HashSet<usize> = faces.iter().map(|f| f.0).collect();
        // The faces naming each entity, in face order (made only when a seam moved).
        let mut naming: std::collections::HashMap<Label, Vec<usize>> =
            std::collections::HashMap::new();
        for (k, o) in self.topology.origins.faces.iter().enumerate() {
            if let Some(label) = &o.entity {
                naming.entry(label.clone()).or_default().push(k);
            }
        }
        // Per entity that a moved face names: the surfaces to list after it.
        let mut added: Vec<(usize, Vec<Entity>)> = Vec::new();
        let mut done: std::collections::HashSet<Label> = std::collections::HashSet::new();
        for &f in faces {
            let Some(label) = self
                .topology
                .origins
                .faces
                .get(f.0)
                .and_then(|o| o.entity.clone())
            else {
                continue;
            };
            if !done.insert(label.clone()) {
                continue;
            }
            let Some(k) = self.entities.iter().position(|e| e.id == label) else {
                continue;
            };
            if !matches!(self.entities[k].geometry, Geometry::Surface(_)) {
                continue;
            }
            let all = naming.get(&label).map_or(&[][..], Vec::as_slice);
            // Does a face still carry the surface as read?
            let read_carried = all.iter().any(|&g| {
                !moved.contains(&g)
                    && self.topology.model.faces.get(g).is_some_and(|face| {
                        matches!(&self.entities[k].geometry, Geometry::Surface(x) if *x == face.surface)
                    })
            });
            let mut extra: Vec<Entity> = Vec::new();
            let mut first = !read_carried;
            for &g in all.iter().filter(|g| moved.contains(g)) {
                let (Some(face), Some(origin)) = (
                    self.topology.model.faces.get(g),
                    self.topology.origins.faces.get(g),
                ) else {
                    continue;
                };
                let surface = Geometry::Surface(face.surface.clone());
                let face_label = origin.id.clone();
                let entity = &mut self.entities[k];
                if first {
                    // No face carries the surface as read: the entity becomes this one.
                    first = false;
                    entity.geometry = surface;
                    // A range declared in the old parameters (IGES 128 U(0)..V(1)) says
                    // nothing of the new ones.
                    entity.meta.parameter_range = None;
                    continue;
                }
                if entity.geometry == surface {
                    continue;
                }
                entity.meta.used_by.retain(|u| *u != face_label);
                let listed = extra.iter().position(|e| e.geometry == surface);
                let target = match listed {
                    Some(i) => {
                        extra[i].meta.used_by.push(face_label);
                        extra[i].id.clone()
                    }
                    None => {
                        let mut e = entity.clone();
                        e.id = compact_str::format_compact!("{label}@{face_label}");
                        e.geometry = surface;
                        e.meta.parameter_range = None;
                        e.meta.used_by = vec![face_label];
                        let id = e.id.clone();
                        extra.push(e);
                        id
                    }
                };
                if let Some(o) = self.topology.origins.faces.get_mut(g) {
                    o.entity = Some(target);
                }
            }
            if !extra.is_empty() {
                added.push((k, extra));
            }
        }
        // Each entity's new neighbours listed right after it (from the last, so that the
        // positions before stay valid).
        added.sort_by_key(|(k, _)| *k);
        for (k, extra) in added.into_iter().rev() {
            let at = (k + 1).min(self.entities.len());
            self.entities.splice(at..at, extra);
        }
    }

    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics
            .iter()
            .any(|d| d.severity == Severity::Error)
    }
}

/// One B-spline curve or surface with where it came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entity {
    /// The id in the source file: `#17` (STEP) or `D5` (IGES DE pointer); for geometry
    /// made in memory, any unique label.
    pub id: Label,
    /// The exact geometry.
    pub geometry: Geometry,
    /// The source entity.
    pub source: Source,
    /// Format metadata kept for information and for writing back.
    pub meta: Meta,
}

/// Provenance of an entity.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Source {
    /// Entity type as the file names it: `B_SPLINE_CURVE_WITH_KNOTS`,
    /// `(B_SPLINE_CURVE,RATIONAL_B_SPLINE_CURVE,...)`, `126`, `128`. Borrowed when it is a
    /// name the reader knows (no allocation per entity).
    pub entity: Cow<'static, str>,
    /// 1-based line where the entity starts (STEP instance line; IGES first D line).
    pub line: Option<usize>,
}

/// Format metadata of an entity: flags and forms that are "for information" in the
/// standards. Readers keep them as written and *check* them against the data (a mismatch is
/// a diagnostic, never a silent change); writers compute them from the data.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Meta {
    /// STEP `name` attribute, IGES entity label (DE field 18) or 406 name property.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// STEP `curve_form`/`surface_form` in lower case (`circular_arc`), or the IGES form
    /// number as a string. Borrowed for the standard's values (no allocation per entity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub form: Option<Cow<'static, str>>,
    /// STEP `closed_curve`/`u_closed`, IGES PROP2 (126) / PROP1 (128).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_u: Option<bool>,
    /// STEP `v_closed`, IGES 128 PROP2.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_v: Option<bool>,
    /// IGES PROP4 (126/128): periodic flag as written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub periodic_u: Option<bool>,
    /// IGES 128 PROP5.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub periodic_v: Option<bool>,
    /// STEP `self_intersect`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_intersect: Option<bool>,
    /// STEP `knot_spec` in lower case (`piecewise_bezier_knots`), or the implicit-knot
    /// subtype the knots were synthesised for (`bezier`, `uniform`, `quasi_uniform`).
    /// Borrowed for the standard's values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub knot_spec: Option<Cow<'static, str>>,
    /// What the geometry was in the source file (a circle, a cylinder ...), kept through
    /// conversion; writers map it to STEP `curve_form`/`surface_form` and to IGES 126 forms
    /// 1-5 / 128 forms 1-8 when the geometry agrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
    /// The precision [`Meta::shape`] was checked to when read, when the check needed more
    /// than the geometry's own digits give: an IGES 126/128 written with few digits (a
    /// circle's weight as `0.70710678`) is its kind to the precision the file carries
    /// (`exchange::iges::form`); writers check the label to at least this.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape_tolerance: Option<f64>,
    /// IGES 126 `V(0), V(1)` / 128 `U(0), U(1), V(0), V(1)`: the parameter range the file
    /// declares (kept; geometry is trimmed to it only on request). Boxed, as
    /// [`Meta::plane_normal`]: IGES-only and rare, they would otherwise make every entity
    /// of every read (a large file has hundreds of thousands) 56 bytes larger.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter_range: Option<Box<ParameterRange>>,
    /// IGES 126 unit normal of a planar curve (PROP1 = 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_normal: Option<Box<Point3>>,
    /// IGES: the DE pointers of the 124 transformation chain applied to the poles.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transforms_applied: Vec<Label>,
    /// IGES: the 144/186/142 entities that use this one (their trims/topology are not
    /// applied).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub used_by: Vec<Label>,
}

/// A declared parameter range: `u` for curves, `u` and `v` for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParameterRange {
    /// `(start, end)` in u (IGES `V(0), V(1)` for curves, `U(0), U(1)` for surfaces).
    pub u: (f64, f64),
    /// `(start, end)` in v, for surfaces.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v: Option<(f64, f64)>,
}

impl ParameterRange {
    /// Whether `(a, b)` and `(c, d)` are the same range up to rounding at the scale of
    /// `domain` (four units in the last place of its largest end).
    pub(crate) fn same_within_rounding(x: (f64, f64), y: (f64, f64), domain: (f64, f64)) -> bool {
        let scale = domain.0.abs().max(domain.1.abs()).max(f64::MIN_POSITIVE);
        let ulps = 4.0 * f64::EPSILON * scale;
        (x.0 - y.0).abs() <= ulps && (x.1 - y.1).abs() <= ulps
    }
}

/// The format-neutral kind of a source curve or surface that nurbsx converted to NURBS.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A line segment.
    Line,
    /// A polyline.
    Polyline,
    /// A circle or circular arc.
    CircularArc,
    /// An ellipse or elliptic arc.
    EllipticArc,
    /// A parabolic arc.
    ParabolicArc,
    /// A hyperbolic arc.
    HyperbolicArc,
    /// A plane.
    Plane,
    /// A right circular cylinder.
    Cylinder,
    /// A right circular cone.
    Cone,
    /// A sphere.
    Sphere,
    /// A torus.
    Torus,
    /// A surface of revolution.
    Revolution,
    /// A surface of linear extrusion (tabulated cylinder).
    Extrusion,
    /// A ruled surface.
    Ruled,
}
