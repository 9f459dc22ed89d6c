//! STEP product structure -> placed parts: the assembly of ISO 10303-44 (product
//! definitions used by others through next_assembly_usage_occurrence) with the placements of
//! AP214's context_dependent_shape_representation, and ISO 10303-43 mapped items.
//!
//! - A product definition's shape is the shape_representation its
//!   shape_definition_representation names, together with the representations joined to it
//!   by a shape_representation_relationship without transformation (same coordinates).
//! - A usage is placed by the representation_relationship_with_transformation of the
//!   context_dependent_shape_representation whose product_definition_shape names it. Its
//!   item_defined_transformation maps `transform_item_1` onto `transform_item_2` (ISO
//!   10303-43 item_defined_transformation): with `A(p)` the matrix of axis placement `p`
//!   (ISO 10303-42 `build_axes`: columns x, y, z and the location), a point `x` of the
//!   component goes to `A(item_2) A(item_1)^-1 x` in the assembly. The item in the
//!   component's representation is `transform_item_1` when the component's representation
//!   is `rep_1` (ISO 10303-43); writers that swap `rep_1` and `rep_2` are read the other way.
//! - A mapped_item places its representation_map's `mapped_representation` by
//!   `A(mapping_target) A(mapping_origin)^-1`.
//!
//! The tree becomes [`Assembly`]s (one per product definition, named by its product; a part
//! used twice is one definition with two instances), placed by
//! [`place_all`](crate::exchange::assembly::place_all).

use std::collections::{HashMap, HashSet};

use nurbsx_parsers::step::geometry::GeometryRecord as G;
use nurbsx_parsers::step::product::{ProductItem, ProductRecord as P};
use nurbsx_parsers::step::schema::DecodeError;
use nurbsx_parsers::step::{RawInstance, Scanned};

use super::geometry::{Converter, Items};
use crate::exchange::assembly::{Definitions, parts_by_id, place_all};
use crate::exchange::{Diagnostic, Entity, Label, Location, Origin, Topology};
use crate::nurbs::sweep::Frame;
use crate::nurbs::transform::{Affine, IDENTITY, compose};
use crate::nurbs::{Geometry, bounding_box_diagonal};
use crate::topology::{Assembly, AssemblyId, Instance, Model, Part};

/// The decoded product-structure instances by id.
pub(super) type Products<'a> = HashMap<u64, ProductItem<'a>>;

/// The placements the product structure reads as frames (ISO 10303-43
/// item_defined_transformation's two items, representation_map's `mapping_origin` and
/// mapped_item's `mapping_target`) and the directions they name: the decoded items
/// [`apply`] needs of the file's placements and directions.
pub(super) fn frame_items(products: &Products<'_>, items: &Items<'_>) -> HashSet<u64> {
    let mut out = HashSet::new();
    for item in products.values() {
        let ids: [Option<u64>; 2] = match item.record {
            P::ItemDefinedTransformation {
                transform_item_1,
                transform_item_2,
            } => [Some(transform_item_1), Some(transform_item_2)],
            P::RepresentationMap { mapping_origin, .. } => [Some(mapping_origin), None],
            P::MappedItem { mapping_target, .. } => [Some(mapping_target), None],
            _ => continue,
        };
        for id in ids.into_iter().flatten() {
            out.insert(id);
            match items.get(&id).map(|i| &i.record) {
                Some(G::Axis2Placement3d {
                    axis,
                    ref_direction,
                    ..
                }) => out.extend(axis.iter().chain(ref_direction)),
                Some(G::Axis2Placement2d { ref_direction, .. }) => out.extend(ref_direction),
                _ => {}
            }
        }
    }
    out
}

/// Decodes the product-structure candidates; schema and syntax errors are diagnostics.
pub(super) fn decode<'a>(
    s: &Scanned<'a>,
    candidates: &[&RawInstance<'a>],
    diagnostics: &mut Vec<Diagnostic>,
    to_diagnostic: impl Fn(DecodeError) -> Diagnostic,
) -> Products<'a> {
    let mut out = Products::new();
    for raw in candidates {
        match s.product_item(raw) {
            Ok(Some(item)) => {
                out.insert(raw.id, item);
            }
            Ok(None) => {}
            Err(e) => diagnostics.push(to_diagnostic(e)),
        }
    }
    out
}

/// An axis placement's matrix `[x y z | location]` (local -> parent coordinates).
fn matrix(f: &Frame) -> Affine {
    std::array::from_fn(|r| [f.x[r], f.y[r], f.z[r], f.origin[r]])
}

/// The inverse of a rigid map (orthonormal linear part): `R^T (x - t)`.
fn inverse_rigid(m: &Affine) -> Affine {
    std::array::from_fn(|r| {
        let t = -(0..3).map(|k| m[k][r] * m[k][3]).sum::<f64>();
        [m[0][r], m[1][r], m[2][r], t]
    })
}

/// A node of the tree: a product definition, or a representation placed by a mapped item.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Definition(u64),
    Representation(u64),
}

impl Key {
    fn id(self) -> u64 {
        match self {
            Key::Definition(i) | Key::Representation(i) => i,
        }
    }
}

/// One instance before it is an [`Instance`]: what it places and the entity that says so.
struct Use {
    name: Option<String>,
    source: Option<u64>,
    placement: Affine,
    part: Result<Part, Key>,
}

struct Reader<'r, 'm, 's, 'a> {
    conv: &'r Converter<'m, 's, 'a>,
    products: &'r Products<'a>,
    diagnostics: Vec<Diagnostic>,
}

impl<'r, 'a> Reader<'r, '_, '_, 'a> {
    fn record(&self, id: u64) -> Option<&'r P<'a>> {
        self.products.get(&id).map(|i| &i.record)
    }

    fn warn(&mut self, id: u64, code: &str, message: String) {
        self.diagnostics
            .push(Diagnostic::warning(code, message, self.conv.location(id)));
    }

    /// The product name of a product definition: PRODUCT.name, else its id, else `#pd`.
    fn product_name(&self, pd: u64) -> String {
        let product = match self.record(pd) {
            Some(P::Definition { formation }) => match self.record(*formation) {
                Some(P::Formation { of_product }) => self.record(*of_product),
                _ => None,
            },
            _ => None,
        };
        let text = |s: &Option<nurbsx_parsers::step::StepString<'_>>| {
            s.as_ref()
                .map(|s| s.decode_lossy().into_owned())
                .filter(|s| !s.is_empty())
        };
        match product {
            Some(P::Product { id, name }) => text(name).or_else(|| text(id)),
            _ => None,
        }
        .unwrap_or_else(|| super::instance_label(pd).into())
    }

    /// An axis placement's matrix, or a located error.
    fn frame(&self, id: u64, from: u64) -> Result<Affine, Diagnostic> {
        self.conv.frame(id, from).map(|f| matrix(&f))
    }
}

/// Reads the assembly of `products` and applies its placements to `topology` (whose items
/// are each part once, in its own coordinates). Returns what it did and found. A file without
/// usages or mapped items is left as it is.
pub(super) fn apply<'a>(
    conv: &Converter<'_, '_, 'a>,
    products: &Products<'a>,
    entities: &[Entity],
    topology: &mut Topology,
    max_items: usize,
) -> Vec<Diagnostic> {
    let has_tree = products
        .values()
        .any(|p| matches!(p.record, P::Usage { .. } | P::MappedItem { .. }));
    if !has_tree {
        return Vec::new();
    }
    let mut r = Reader {
        conv,
        products,
        diagnostics: Vec::new(),
    };
    let mut ids: Vec<u64> = products.keys().copied().collect();
    ids.sort_unstable();

    // What the records say, in file order.
    let mut shape_of: HashMap<u64, Key> = HashMap::new(); // product_definition_shape -> definition / usage
    let mut usages: Vec<u64> = Vec::new();
    for &id in &ids {
        match r.record(id) {
            Some(P::DefinitionShape { definition }) => match r.record(*definition) {
                Some(P::Definition { .. }) => {
                    shape_of.insert(id, Key::Definition(*definition));
                }
                Some(P::Usage { .. }) => {
                    // A usage's shape: recorded with the usage's id.
                    shape_of.insert(id, Key::Representation(*definition));
                }
                _ => {}
            },
            Some(P::Usage { .. }) => usages.push(id),
            _ => {}
        }
    }
    // Representations of each definition, and the placement relationship of each usage.
    let mut reps_of: HashMap<u64, Vec<u64>> = HashMap::new();
    let mut placement_of: HashMap<u64, u64> = HashMap::new(); // usage -> relationship
    for &id in &ids {
        match r.record(id) {
            Some(P::ShapeDefinitionRepresentation {
                definition,
                used_representation,
            }) => {
                if let Some(Key::Definition(pd)) = shape_of.get(definition) {
                    reps_of.entry(*pd).or_default().push(*used_representation);
                }
            }
            Some(P::ContextDependentShapeRepresentation {
                representation_relation,
                represented_product_relation,
            }) => {
                if let Some(Key::Representation(usage)) = shape_of.get(represented_product_relation)
                {
                    placement_of.insert(*usage, *representation_relation);
                }
            }
            _ => {}
        }
    }
    // Representations in the same coordinates (relationships without transformation that
    // place no usage).
    let placing: HashSet<u64> = placement_of.values().copied().collect();
    let mut joined: HashMap<u64, Vec<u64>> = HashMap::new();
    for &id in &ids {
        if let Some(P::RepresentationRelationship {
            rep_1,
            rep_2,
            transformation_operator: None,
        }) = r.record(id)
        {
            if !placing.contains(&id) {
                joined.entry(*rep_1).or_default().push(*rep_2);
                joined.entry(*rep_2).or_default().push(*rep_1);
            }
        }
    }
    let closure = |start: &[u64]| -> Vec<u64> {
        let mut seen: Vec<u64> = Vec::new();
        let mut stack: Vec<u64> = start.to_vec();
        while let Some(rep) = stack.pop() {
            if seen.contains(&rep) {
                continue;
            }
            seen.push(rep);
            stack.extend(joined.get(&rep).into_iter().flatten().copied());
        }
        seen.sort_unstable();
        seen
    };

    set_edges(&r, &ids, entities, topology);
    // The nodes: every definition with a shape or a usage, and every mapped representation.
    let by_id = parts_by_id(&topology.origins);
    let mut keys: Vec<Key> = Vec::new();
    let mut index: HashMap<Key, usize> = HashMap::new();
    let mut node = |k: Key, keys: &mut Vec<Key>| -> usize {
        *index.entry(k).or_insert_with(|| {
            keys.push(k);
            keys.len() - 1
        })
    };
    let mut definitions: Vec<u64> = reps_of.keys().copied().collect();
    for &u in &usages {
        if let Some(P::Usage {
            relating, related, ..
        }) = r.record(u)
        {
            definitions.extend([*relating, *related]);
        }
    }
    definitions.sort_unstable();
    definitions.dedup();
    for &pd in &definitions {
        node(Key::Definition(pd), &mut keys);
    }
    let mut uses: Vec<Vec<Use>> = Vec::new();
    let mut not_placed_sets = 0usize;
    let mut k = 0;
    while k < keys.len() {
        let key = keys[k];
        let reps = match key {
            Key::Definition(pd) => closure(reps_of.get(&pd).map_or(&[][..], |v| v)),
            Key::Representation(rep) => closure(&[rep]),
        };
        let mut list: Vec<Use> = Vec::new();
        let mut mapped_reps: Vec<u64> = Vec::new();
        let items: Vec<u64> = reps
            .iter()
            .filter_map(|rep| match r.record(*rep) {
                Some(P::ShapeRepresentation { items, .. }) => Some(items.clone()),
                _ => None,
            })
            .flatten()
            .collect();
        for item in items {
            let leaf = |p: Part| Use {
                name: None,
                source: None,
                placement: IDENTITY,
                part: Ok(p),
            };
            let id = super::instance_label(item);
            if let Some(&p) = by_id.get(id.as_str()) {
                list.push(leaf(p));
                continue;
            }
            if let Some(P::MappedItem {
                mapping_source,
                mapping_target,
            }) = r.record(item)
            {
                let Some(P::RepresentationMap {
                    mapping_origin,
                    mapped_representation,
                }) = r.record(*mapping_source)
                else {
                    r.warn(
                        item,
                        "assembly.not_placed",
                        format!("MAPPED_ITEM #{item}: #{mapping_source} is not a REPRESENTATION_MAP; the mapped shape is not placed"),
                    );
                    continue;
                };
                let (origin, rep) = (*mapping_origin, *mapped_representation);
                match (r.frame(origin, item), r.frame(*mapping_target, item)) {
                    (Ok(from), Ok(to)) => {
                        mapped_reps.extend(closure(&[rep]));
                        list.push(Use {
                            name: Some(super::instance_label(item).into()),
                            source: Some(item),
                            placement: compose(&to, &inverse_rigid(&from)),
                            part: Err(Key::Representation(rep)),
                        });
                    }
                    (Err(d), _) | (_, Err(d)) => r.diagnostics.push(d),
                }
                continue;
            }
            match conv.items.get(&item).map(|i| &i.record) {
                Some(G::ShellBasedSurfaceModel { sbsm_boundary: s })
                | Some(G::FaceBasedSurfaceModel { fbsm_faces: s }) => {
                    for shell in s {
                        if let Some(&p) = by_id.get(super::instance_label(*shell).as_str()) {
                            list.push(leaf(p));
                        }
                    }
                }
                Some(G::GeometricSet { elements }) => {
                    // Its curves are free edges (`set_edges`); points and surfaces stay
                    // where the product's own coordinates put them.
                    let mut all = true;
                    for e in elements {
                        match by_id.get(super::instance_label(*e).as_str()) {
                            Some(&p @ Part::Edge(_)) => list.push(leaf(p)),
                            _ => all = false,
                        }
                    }
                    if !all {
                        not_placed_sets += 1;
                    }
                }
                _ => {}
            }
        }
        if let Key::Definition(pd) = key {
            for &u in &usages {
                let Some(P::Usage {
                    id: uid,
                    name,
                    relating,
                    related,
                }) = r.record(u)
                else {
                    continue;
                };
                if *relating != pd {
                    continue;
                }
                let related = *related;
                let label = [name, uid]
                    .into_iter()
                    .flatten()
                    .map(|s| s.decode_lossy().into_owned())
                    .find(|s| !s.is_empty())
                    .unwrap_or_else(|| super::instance_label(u).into());
                let child_reps = closure(reps_of.get(&related).map_or(&[][..], |v| v));
                let placement = match placement_of.get(&u) {
                    None if child_reps.iter().any(|c| mapped_reps.contains(c)) => continue,
                    None => {
                        r.warn(
                            u,
                            "assembly.placement_missing",
                            format!("NEXT_ASSEMBLY_USAGE_OCCURRENCE #{u} ('{label}') has no CONTEXT_DEPENDENT_SHAPE_REPRESENTATION: placed where its own coordinates put it"),
                        );
                        IDENTITY
                    }
                    Some(&rel) => match usage_placement(&r, u, rel, &child_reps) {
                        Ok(m) => m,
                        Err(d) => {
                            r.diagnostics.push(d);
                            continue;
                        }
                    },
                };
                list.push(Use {
                    name: Some(label),
                    source: Some(u),
                    placement,
                    part: Err(Key::Definition(related)),
                });
            }
        }
        for u in &list {
            if let Err(child) = u.part {
                node(child, &mut keys);
            }
        }
        uses.push(list);
        k += 1;
    }

    // The definitions as assemblies.
    let mut defs = Model {
        assemblies: Vec::with_capacity(keys.len()),
        ..Model::default()
    };
    let mut sources: Vec<Vec<Option<u64>>> = Vec::with_capacity(keys.len());
    for (key, list) in keys.iter().zip(uses) {
        let name = match key {
            Key::Definition(pd) => r.product_name(*pd),
            Key::Representation(rep) => match r.record(*rep) {
                Some(P::ShapeRepresentation { name: Some(n), .. })
                    if !n.decode_lossy().is_empty() =>
                {
                    n.decode_lossy().into_owned()
                }
                _ => super::instance_label(*rep).into(),
            },
        };
        let mut instances = Vec::with_capacity(list.len());
        let mut src = Vec::with_capacity(list.len());
        for u in list {
            let part = match u.part {
                Ok(p) => p,
                Err(child) => Part::Assembly(AssemblyId(index[&child])),
            };
            instances.push(Instance {
                name: u.name,
                placement: u.placement,
                part,
            });
            src.push(u.source);
        }
        defs.add_assembly(Assembly { name, instances });
        sources.push(src);
    }
    if not_placed_sets > 0 {
        r.diagnostics.push(Diagnostic::warning(
            "assembly.geometry_not_placed",
            format!("{not_placed_sets} GEOMETRIC_SET(s) in the products' shapes hold points or surfaces (or curves that could not be read), which are kept once, in their own product's coordinates (not placed); their curves are placed"),
            Location::default(),
        )
        .not_carried());
    }
    let definitions = Definitions {
        ids: keys.iter().map(|k| format!("#{}", k.id())).collect(),
        sources: sources
            .into_iter()
            .map(|l| {
                l.into_iter()
                    .map(|s| s.map_or_else(String::new, |i| super::instance_label(i).into()))
                    .collect()
            })
            .collect(),
        model: defs,
    };
    r.diagnostics
        .extend(place_all(&definitions, topology, max_items, &|id: &str| {
            conv.location(id.trim_start_matches('#').parse().unwrap_or(0))
        }));
    r.diagnostics
}

/// The 3-D curves of the GEOMETRIC_SETs (ISO 10303-42 clause 6.4.3 geometric_set) that the
/// shape representations hold become free edges of `topology` (each over its whole curve,
/// between vertices at its ends, named by the curve's id), so that an instance of their
/// product places them as it places the product's solids; their entities become the edges'
/// geometry, so writers write them once per placed copy.
fn set_edges(
    r: &Reader<'_, '_, '_, '_>,
    ids: &[u64],
    entities: &[Entity],
    topology: &mut Topology,
) {
    let mut curves: Vec<u64> = Vec::new();
    for &id in ids {
        let Some(P::ShapeRepresentation { items, .. }) = r.record(id) else {
            continue;
        };
        for item in items {
            if let Some(G::GeometricSet { elements }) = r.conv.items.get(item).map(|i| &i.record) {
                curves.extend(elements);
            }
        }
    }
    if curves.is_empty() {
        return;
    }
    curves.sort_unstable();
    curves.dedup();
    let taken: HashSet<Label> = topology
        .origins
        .edges
        .iter()
        .map(|o| o.id.clone())
        .collect();
    let by_id: HashMap<&str, &Entity> = entities.iter().map(|e| (e.id.as_str(), e)).collect();
    // Free curves join nothing: their vertices are their own ends, exact; the tolerance is
    // the model's (so a writer declares no new one), or 1e-7 of the curve's size.
    let model_tolerance = topology
        .model
        .edges
        .iter()
        .map(|e| e.tolerance)
        .fold(0.0f64, f64::max);
    for c in curves {
        let id = super::instance_label(c);
        let Some(entity) = by_id.get(id.as_str()) else {
            continue;
        };
        let Geometry::Curve(curve) = &entity.geometry else {
            continue;
        };
        if curve.dimension() != 3 || taken.contains(&id) {
            continue;
        }
        let range = curve.domain();
        let (Ok(a), Ok(b)) = (curve.point_at(range.0), curve.point_at(range.1)) else {
            continue;
        };
        let tolerance = if model_tolerance > 0.0 {
            model_tolerance
        } else {
            1e-7 * bounding_box_diagonal(curve.control_points()).max(1.0)
        };
        let model = &mut topology.model;
        let Ok(start) = model.add_vertex(a, tolerance) else {
            continue;
        };
        let end = if a == b {
            start
        } else {
            match model.add_vertex(b, tolerance) {
                Ok(v) => v,
                Err(_) => {
                    model.vertices.pop();
                    continue;
                }
            }
        };
        if model
            .add_edge(curve.clone(), range, start, end, tolerance)
            .is_err()
        {
            model.vertices.truncate(start.0);
            continue;
        }
        let origin = |suffix: &str| Origin {
            id: compact_str::format_compact!("{id}{suffix}"),
            source: entity.source.clone(),
            name: None,
            entity: None,
        };
        topology.origins.vertices.push(origin(".start"));
        if end != start {
            topology.origins.vertices.push(origin(".end"));
        }
        topology.origins.edges.push(Origin {
            entity: Some(id.clone()),
            ..origin("")
        });
    }
}

/// The placement of usage `u` by relationship `rel` (see the module documentation).
fn usage_placement(
    r: &Reader<'_, '_, '_, '_>,
    u: u64,
    rel: u64,
    child_reps: &[u64],
) -> Result<Affine, Diagnostic> {
    let refuse = |m: String| {
        Diagnostic::error(
            "assembly.not_placed",
            format!("{m}; the instance is not placed"),
            r.conv.location(rel),
        )
    };
    let Some(P::RepresentationRelationship {
        rep_1,
        rep_2,
        transformation_operator,
    }) = r.record(rel)
    else {
        return Err(refuse(format!(
            "usage #{u}: #{rel} is not a REPRESENTATION_RELATIONSHIP"
        )));
    };
    let Some(op) = transformation_operator else {
        // Same coordinates.
        return Ok(IDENTITY);
    };
    let Some(P::ItemDefinedTransformation {
        transform_item_1,
        transform_item_2,
    }) = r.record(*op)
    else {
        return Err(refuse(format!(
            "usage #{u}: transformation #{op} is not an ITEM_DEFINED_TRANSFORMATION (a CARTESIAN_TRANSFORMATION_OPERATOR is not read)"
        )));
    };
    let a1 = r.frame(*transform_item_1, *op)?;
    let a2 = r.frame(*transform_item_2, *op)?;
    // rep_1 is the component's representation (ISO 10303-43); some writers swap them.
    let swapped = !child_reps.contains(rep_1) && child_reps.contains(rep_2);
    Ok(if swapped {
        compose(&a1, &inverse_rigid(&a2))
    } else {
        compose(&a2, &inverse_rigid(&a1))
    })
}
