//! Placing the instances of an assembly, whatever format described it: the definitions
//! (one [`Assembly`] per product or subfigure, read by `step::assembly` from the ISO
//! 10303-44 product structure or by `iges::topology` from IGES 5.3 308/408 subfigures)
//! are flattened by [`Model::flatten`] (no recursion; cycles, nesting deeper than
//! [`MAX_DEPTH`] and more than [`MAX_INSTANCES`] leaves refused) and every leaf is copied
//! into root coordinates by [`Model::place`] with exactly transformed geometry. Items that no
//! definition holds stay as they are. The definitions and their items before placement are
//! kept beside the placed model ([`ProductStructure`]) for writers of product structure.

use std::collections::{HashMap, HashSet};

use super::{Diagnostic, Location, Origin, Origins, PlacedInstance, ProductStructure, Topology};
use crate::nurbs::transform::{IDENTITY, compose};
use crate::topology::{AssemblyId, EdgeId, FaceId, Model, Part, ShellId, SolidId, TopologyError};

/// Deepest nesting of assemblies followed.
pub(crate) const MAX_DEPTH: usize = 64;
/// Most leaf instances one file's assemblies may expand to (a sub-assembly shared by
/// several others multiplies its instances).
pub(crate) const MAX_INSTANCES: usize = 100_000;

/// A file's assembly definitions over the parts of its topology.
pub(crate) struct Definitions {
    /// One assembly per definition; leaf instances name the topology's solids, shells,
    /// faces and edges.
    pub model: Model,
    /// The file id of each definition (`#5`, `D45`), for messages.
    pub ids: Vec<String>,
    /// Per definition, per instance: the entity that places it (`#464`, `D47`; empty for a
    /// definition's own items).
    pub sources: Vec<Vec<String>>,
}

/// The model's items by their file id (`#41`, `D45`).
pub(crate) fn parts_by_id(origins: &Origins) -> HashMap<&str, Part> {
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

/// Applies the placements of `defs` to `topology` (whose items are each definition's once,
/// in its own coordinates): the result holds every instance's items in root coordinates,
/// their origin ids suffixed `@path` with the instance names from the root, and the list of
/// named instances. On a refused tree (a cycle, a limit) the topology is left as it is and
/// the error says so, located by `locate` at the definition it names.
pub(crate) fn place_all(
    defs: &Definitions,
    topology: &mut Topology,
    max_items: usize,
    locate: &dyn Fn(&str) -> Location,
) -> Vec<Diagnostic> {
    let mut diagnostics = Vec::new();
    let mut child_of = vec![false; defs.model.assemblies.len()];
    for a in &defs.model.assemblies {
        for inst in &a.instances {
            if let Part::Assembly(c) = inst.part {
                if let Some(x) = child_of.get_mut(c.0) {
                    *x = true;
                }
            }
        }
    }
    let roots: Vec<usize> = (0..defs.model.assemblies.len())
        .filter(|&i| !child_of[i] && !defs.model.assemblies[i].instances.is_empty())
        .collect();
    let describe = |i: usize| format!("{} '{}'", defs.ids[i], defs.model.assemblies[i].name);
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
                chain.first().map_or("", |a| defs.ids[a.0].as_str()),
            ),
            TopologyError::AssemblyTooLarge { root, what, limit } => (
                format!(
                    "the assembly {} expands beyond {limit} {what}",
                    describe(root.0)
                ),
                defs.ids[root.0].as_str(),
            ),
            other => (other.to_string(), ""),
        };
        Diagnostic::error(
            "assembly.refused",
            format!(
                "{message}; no placement is applied: every part is kept once, in its own coordinates"
            ),
            locate(at),
        )
    };
    // Nodes no root reaches sit on a cycle (or under one): flattening one names it.
    let mut reached = vec![false; defs.model.assemblies.len()];
    let mut stack: Vec<usize> = roots.clone();
    while let Some(i) = stack.pop() {
        if std::mem::replace(&mut reached[i], true) {
            continue;
        }
        for inst in &defs.model.assemblies[i].instances {
            if let Part::Assembly(a) = inst.part {
                stack.push(a.0);
            }
        }
    }
    if let Some(i) = (0..defs.model.assemblies.len()).find(|&i| !reached[i]) {
        let e = match defs.model.flatten(AssemblyId(i), MAX_DEPTH, MAX_INSTANCES) {
            Err(e) => e,
            Ok(_) => TopologyError::AssemblyCycle {
                chain: vec![AssemblyId(i)],
            },
        };
        diagnostics.push(located(&e));
        return diagnostics;
    }
    let mut leaves = Vec::new();
    for &root in &roots {
        match defs
            .model
            .flatten(AssemblyId(root), MAX_DEPTH, MAX_INSTANCES)
        {
            Ok(l) => leaves.push((root, l)),
            Err(e) => {
                diagnostics.push(located(&e));
                return diagnostics;
            }
        }
    }
    let total: usize = leaves.iter().map(|(_, l)| l.len()).sum();
    if total > MAX_INSTANCES {
        diagnostics.push(located(&TopologyError::AssemblyTooLarge {
            root: AssemblyId(roots[0]),
            what: "instances",
            limit: MAX_INSTANCES,
        }));
        return diagnostics;
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
        diagnostics.push(Diagnostic::error(
            "limit.entities",
            format!("placing the assembly's instances would make {budget} vertices, edges, faces, shells and solids, more than the limit of {max_items}; no placement is applied: every part is kept once, in its own coordinates"),
            Location::default(),
        ));
        return diagnostics;
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
                let inst = &defs.model.assemblies[asm].instances[i];
                world = compose(&world, &inst.placement);
                if let Some(n) = &inst.name {
                    names.push(n.clone());
                    let key = (*root, leaf.path[..=depth].to_vec());
                    let next = instances.len();
                    let at = *instance_at.entry(key).or_insert(next);
                    if at == next {
                        let product = match inst.part {
                            Part::Assembly(a) => defs.model.assemblies[a.0].name.clone(),
                            _ => String::new(),
                        };
                        instances.push(PlacedInstance {
                            path: names.join("/"),
                            id: defs.sources[asm][i].clone(),
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
                            compact_str::format_compact!("{}@{path}", o.id)
                        },
                        ..o.clone()
                    };
                    extend(&mut out.origins, &topology.origins, &copied, name);
                    if let (Some(at), Some(id)) = (owner, placed_id(&out.origins, placed)) {
                        instances[at].places.push(id);
                    }
                }
                Err(e) => {
                    diagnostics.push(located(&e));
                    return diagnostics;
                }
            }
        }
    }
    // Everything no product's shape holds, as it is.
    let loose = unowned(source, &owned);
    for &part in &loose {
        if let Ok((_, copied)) = source.place(part, &IDENTITY, &mut out.model) {
            extend(&mut out.origins, &topology.origins, &copied, Origin::clone);
        }
    }
    let named = instances.len();
    diagnostics.push(Diagnostic::info(
        "assembly.placed",
        format!(
            "assembly placements applied: {total} part instance(s) under {named} named instance(s) of {} product(s) placed in root coordinates ({} solid(s), {} face(s))",
            defs.model.assemblies.len(),
            out.model.solids.len(),
            out.model.faces.len()
        ),
        Location::default(),
    ));
    out.instances = instances;
    // The parts once each with the tree over them, for writers of product structure: the
    // items no product holds go to the first root, as they are.
    let roots: Vec<AssemblyId> = roots.into_iter().map(AssemblyId).collect();
    let defined = std::mem::replace(topology, out);
    if named > 0 {
        let mut model = defined.model;
        model.assemblies = defs.model.assemblies.clone();
        if let Some(first) = roots.first().and_then(|r| model.assemblies.get_mut(r.0)) {
            first
                .instances
                .extend(loose.into_iter().map(|part| crate::topology::Instance {
                    name: None,
                    placement: IDENTITY,
                    part,
                }));
        }
        topology.structure = Some(Box::new(ProductStructure {
            model,
            origins: defined.origins,
            roots,
        }));
    }
    diagnostics
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
    o.map(|o| o.id.to_string())
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
    for (i, held) in edge_held.iter().enumerate() {
        if !held && !owned.contains(&Part::Edge(EdgeId(i))) {
            out.push(Part::Edge(EdgeId(i)));
        }
    }
    out
}
