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
//! used twice is one definition with two instances), [`Model::flatten`] composes the
//! placements without recursion (refusing cycles and oversized trees) and [`Model::place`]
//! copies every leaf into root coordinates with exactly transformed geometry. Items in no
//! product's shape stay as they are.

use std::collections::{HashMap, HashSet};

use nurbsx_parsers::step::geometry::GeometryRecord as G;
use nurbsx_parsers::step::product::{ProductItem, ProductRecord as P};
use nurbsx_parsers::step::schema::DecodeError;
use nurbsx_parsers::step::{RawInstance, Scanned};

use super::geometry::Converter;
use crate::exchange::{Diagnostic, Location, Origin, Origins, PlacedInstance, Topology};
use crate::nurbs::sweep::Frame;
use crate::nurbs::transform::{Affine, IDENTITY, compose};
use crate::topology::{Assembly, AssemblyId, Instance, Model, Part, TopologyError};

/// Deepest nesting of assemblies followed.
pub(super) const MAX_DEPTH: usize = 64;
/// Most leaf instances one file's assemblies may expand to (a sub-assembly shared by
/// several others multiplies its instances).
pub(super) const MAX_INSTANCES: usize = 100_000;

/// The decoded product-structure instances by id.
pub(super) type Products<'a> = HashMap<u64, ProductItem<'a>>;

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
        .unwrap_or_else(|| format!("#{pd}"))
    }

    /// An axis placement's matrix, or a located error.
    fn frame(&self, id: u64, from: u64) -> Result<Affine, Diagnostic> {
        self.conv.frame(id, from).map(|f| matrix(&f))
    }
}

/// The ids of the model's items by their file id (`#41`).
fn parts_by_id(origins: &Origins) -> HashMap<&str, Part> {
    use crate::topology::{EdgeId, FaceId, ShellId, SolidId};
    let mut out = HashMap::new();
    for (i, o) in origins.edges.iter().enumerate() {
        out.insert(o.id.as_str(), Part::Edge(EdgeId(i)));
    }
    for (i, o) in origins.faces.iter().enumerate() {
        out.insert(o.id.as_str(), Part::Face(FaceId(i)));
    }
    for (i, o) in origins.shells.iter().enumerate() {
        out.insert(o.id.as_str(), Part::Shell(ShellId(i)));
    }
    for (i, o) in origins.solids.iter().enumerate() {
        out.insert(o.id.as_str(), Part::Solid(SolidId(i)));
    }
    out
}

/// Reads the assembly of `products` and applies its placements to `topology` (whose items
/// are each part once, in its own coordinates). Returns what it did and found. A file without
/// usages or mapped items is left as it is.
pub(super) fn apply<'a>(
    conv: &Converter<'_, '_, 'a>,
    products: &Products<'a>,
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
            let id = format!("#{item}");
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
                            name: Some(format!("#{item}")),
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
                        if let Some(&p) = by_id.get(format!("#{shell}").as_str()) {
                            list.push(leaf(p));
                        }
                    }
                }
                Some(G::GeometricSet { .. }) => not_placed_sets += 1,
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
                    .unwrap_or_else(|| format!("#{u}"));
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
    let mut child_of = vec![false; keys.len()];
    for (key, list) in keys.iter().zip(uses) {
        let name = match key {
            Key::Definition(pd) => r.product_name(*pd),
            Key::Representation(rep) => match r.record(*rep) {
                Some(P::ShapeRepresentation { name: Some(n), .. })
                    if !n.decode_lossy().is_empty() =>
                {
                    n.decode_lossy().into_owned()
                }
                _ => format!("#{rep}"),
            },
        };
        let mut instances = Vec::with_capacity(list.len());
        let mut src = Vec::with_capacity(list.len());
        for u in list {
            let part = match u.part {
                Ok(p) => p,
                Err(child) => {
                    let i = index[&child];
                    child_of[i] = true;
                    Part::Assembly(AssemblyId(i))
                }
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
            format!("{not_placed_sets} GEOMETRIC_SET(s) in the products' shapes are kept once, in their own product's coordinates (free curves and surfaces are not placed)"),
            Location::default(),
        ));
    }
    let roots: Vec<usize> = (0..keys.len())
        .filter(|&i| !child_of[i] && !defs.assemblies[i].instances.is_empty())
        .collect();
    let describe = |i: usize| format!("#{} '{}'", keys[i].id(), defs.assemblies[i].name);
    let located = |e: &TopologyError| -> Diagnostic {
        let (message, at) = match e {
            TopologyError::AssemblyCycle { chain } => (
                format!(
                    "product definitions contain each other: {}",
                    chain
                        .iter()
                        .map(|a| describe(a.0))
                        .collect::<Vec<_>>()
                        .join(" -> ")
                ),
                chain.first().map_or(0, |a| keys[a.0].id()),
            ),
            TopologyError::AssemblyTooLarge { root, what, limit } => (
                format!(
                    "the assembly {} expands beyond {limit} {what}",
                    describe(root.0)
                ),
                keys[root.0].id(),
            ),
            other => (other.to_string(), 0),
        };
        Diagnostic::error(
            "assembly.refused",
            format!(
                "{message}; no placement is applied: every part is kept once, in its own coordinates"
            ),
            conv.location(at),
        )
    };
    // Nodes no root reaches sit on a cycle (or under one): flattening one names it.
    let mut reached = vec![false; keys.len()];
    let mut stack: Vec<usize> = roots.clone();
    while let Some(i) = stack.pop() {
        if std::mem::replace(&mut reached[i], true) {
            continue;
        }
        for inst in &defs.assemblies[i].instances {
            if let Part::Assembly(a) = inst.part {
                stack.push(a.0);
            }
        }
    }
    if let Some(i) = (0..keys.len()).find(|&i| !reached[i]) {
        let e = match defs.flatten(AssemblyId(i), MAX_DEPTH, MAX_INSTANCES) {
            Err(e) => e,
            Ok(_) => TopologyError::AssemblyCycle {
                chain: vec![AssemblyId(i)],
            },
        };
        r.diagnostics.push(located(&e));
        return r.diagnostics;
    }
    let mut leaves = Vec::new();
    for &root in &roots {
        match defs.flatten(AssemblyId(root), MAX_DEPTH, MAX_INSTANCES) {
            Ok(l) => leaves.push((root, l)),
            Err(e) => {
                r.diagnostics.push(located(&e));
                return r.diagnostics;
            }
        }
    }
    let total: usize = leaves.iter().map(|(_, l)| l.len()).sum();
    if total > MAX_INSTANCES {
        r.diagnostics
            .push(located(&TopologyError::AssemblyTooLarge {
                root: AssemblyId(roots[0]),
                what: "instances",
                limit: MAX_INSTANCES,
            }));
        return r.diagnostics;
    }

    // Copies into root coordinates.
    let source = &topology.model;
    let mut budget = 0usize;
    for (_, list) in &leaves {
        for leaf in list {
            budget = budget.saturating_add(source.part_size(leaf.part).unwrap_or(0));
        }
    }
    if budget > max_items {
        r.diagnostics.push(Diagnostic::error(
            "limit.entities",
            format!("placing the assembly's instances would make {budget} vertices, edges, faces, shells and solids, more than the limit of {max_items}; no placement is applied: every part is kept once, in its own coordinates"),
            Location::default(),
        ));
        return r.diagnostics;
    }
    let mut out = Topology::default();
    let mut owned: HashSet<Part> = HashSet::new();
    let mut instances: Vec<PlacedInstance> = Vec::new();
    let mut instance_at: HashMap<(usize, Vec<usize>), usize> = HashMap::new();
    let mut used_paths: HashSet<(Part, String)> = HashSet::new();
    for (root, list) in &leaves {
        for leaf in list {
            owned.insert(leaf.part);
            // The named instances along the path, recorded once each.
            let mut asm = *root;
            let mut world = IDENTITY;
            let mut names: Vec<String> = Vec::new();
            let mut owner: Option<usize> = None;
            for (depth, &i) in leaf.path.iter().enumerate() {
                let inst = &defs.assemblies[asm].instances[i];
                world = compose(&world, &inst.placement);
                if let Some(n) = &inst.name {
                    names.push(n.clone());
                    let key = (*root, leaf.path[..=depth].to_vec());
                    let next = instances.len();
                    let at = *instance_at.entry(key).or_insert(next);
                    if at == next {
                        let product = match inst.part {
                            Part::Assembly(a) => defs.assemblies[a.0].name.clone(),
                            _ => String::new(),
                        };
                        instances.push(PlacedInstance {
                            path: names.join("/"),
                            id: sources[asm][i].map_or_else(String::new, |s| format!("#{s}")),
                            product,
                            depth: names.len(),
                            placement: inst.placement,
                            world,
                            places: Vec::new(),
                        });
                    }
                    owner = Some(at);
                }
                if let Part::Assembly(a) = inst.part {
                    asm = a.0;
                }
            }
            let mut path = names.join("/");
            if !used_paths.insert((leaf.part, path.clone())) {
                let mut n = 2;
                while !used_paths.insert((leaf.part, format!("{path}[{n}]"))) {
                    n += 1;
                }
                path = format!("{path}[{n}]");
            }
            match source.place(leaf.part, &leaf.placement, &mut out.model) {
                Ok((placed, copied)) => {
                    let name = |o: &Origin| Origin {
                        id: if path.is_empty() {
                            o.id.clone()
                        } else {
                            format!("{}@{path}", o.id)
                        },
                        ..o.clone()
                    };
                    extend(&mut out.origins, &topology.origins, &copied, name);
                    if let (Some(at), Some(id)) = (owner, placed_id(&out.origins, placed)) {
                        instances[at].places.push(id);
                    }
                }
                Err(e) => {
                    r.diagnostics.push(located(&e));
                    return r.diagnostics;
                }
            }
        }
    }
    // Everything no product's shape holds, as it is.
    for part in unowned(source, &owned) {
        if let Ok((_, copied)) = source.place(part, &IDENTITY, &mut out.model) {
            extend(&mut out.origins, &topology.origins, &copied, Origin::clone);
        }
    }
    let named = instances.len();
    r.diagnostics.push(Diagnostic::info(
        "assembly.placed",
        format!(
            "assembly placements applied: {total} part instance(s) under {named} named instance(s) of {} product(s) placed in root coordinates ({} solid(s), {} face(s))",
            keys.len(),
            out.model.solids.len(),
            out.model.faces.len()
        ),
        Location::default(),
    ));
    out.instances = instances;
    *topology = out;
    r.diagnostics
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

/// Appends the origins of copied items, renamed by `name`.
fn extend(
    out: &mut Origins,
    from: &Origins,
    copied: &crate::topology::Copied,
    name: impl Fn(&Origin) -> Origin,
) {
    let pick = |list: &[Origin], i: usize| list.get(i).map(&name).unwrap_or_default();
    out.vertices
        .extend(copied.vertices.iter().map(|v| pick(&from.vertices, v.0)));
    out.edges
        .extend(copied.edges.iter().map(|e| pick(&from.edges, e.0)));
    out.faces
        .extend(copied.faces.iter().map(|f| pick(&from.faces, f.0)));
    out.shells
        .extend(copied.shells.iter().map(|s| pick(&from.shells, s.0)));
    out.solids
        .extend(copied.solids.iter().map(|s| pick(&from.solids, s.0)));
}

/// The origin id of a placed part.
fn placed_id(origins: &Origins, part: Part) -> Option<String> {
    let o = match part {
        Part::Solid(s) => origins.solids.get(s.0),
        Part::Shell(s) => origins.shells.get(s.0),
        Part::Face(f) => origins.faces.get(f.0),
        Part::Edge(e) => origins.edges.get(e.0),
        Part::Assembly(_) => None,
    };
    o.map(|o| o.id.clone())
}

/// The solids, shells, faces and edges of `model` that neither an owned part nor another
/// unowned item holds: each is copied once, as it is.
fn unowned(model: &Model, owned: &HashSet<Part>) -> Vec<Part> {
    use crate::topology::{EdgeId, FaceId, ShellId, SolidId};
    let mut out = Vec::new();
    let mut shell_held = vec![false; model.shells.len()];
    for (i, s) in model.solids.iter().enumerate() {
        for sh in std::iter::once(&s.outer).chain(&s.voids) {
            if let Some(h) = shell_held.get_mut(sh.0) {
                *h = true;
            }
        }
        if !owned.contains(&Part::Solid(SolidId(i))) {
            out.push(Part::Solid(SolidId(i)));
        }
    }
    let mut face_held = vec![false; model.faces.len()];
    for (i, s) in model.shells.iter().enumerate() {
        for (f, _) in &s.faces {
            if let Some(h) = face_held.get_mut(f.0) {
                *h = true;
            }
        }
        if !shell_held[i] && !owned.contains(&Part::Shell(ShellId(i))) {
            out.push(Part::Shell(ShellId(i)));
        }
    }
    let mut edge_held = vec![false; model.edges.len()];
    for (i, f) in model.faces.iter().enumerate() {
        for l in &f.loops {
            for c in &l.coedges {
                if let Some(h) = edge_held.get_mut(c.edge.0) {
                    *h = true;
                }
            }
        }
        if !face_held[i] && !owned.contains(&Part::Face(FaceId(i))) {
            out.push(Part::Face(FaceId(i)));
        }
    }
    for i in 0..model.edges.len() {
        if !edge_held[i] && !owned.contains(&Part::Edge(EdgeId(i))) {
            out.push(Part::Edge(EdgeId(i)));
        }
    }
    out
}
