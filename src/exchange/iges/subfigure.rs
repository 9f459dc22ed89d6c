//! IGES 5.3 subfigures -> placed parts: each 308 Subfigure Definition (section 4.73) is a
//! definition whose members are read as faces (144, 510), shells (514), solids (186) and
//! nested instances (408); each 408 Singular Subfigure Instance (section 4.133) places its
//! 308 by `x' = M (S x + T)`, with `T = (X, Y, Z)`, `S` the scale and `M` the instance's own
//! 124 chain (DE field 7). The 408s that no 308 names are the file's root instances. The
//! placements are applied by [`place_all`](crate::exchange::assembly::place_all), as for
//! STEP assemblies.

use std::collections::{HashMap, HashSet};

use nurbsx_parsers::iges::DirectoryEntry;
use nurbsx_parsers::iges::records::{SubfigureDefinition308, SubfigureInstance408};

use super::read::{Context, decoded, entity_location};
use crate::exchange::assembly::{Definitions, parts_by_id, place_all};
use crate::exchange::{Diagnostic, Location, Meta, Topology};
use crate::nurbs::transform::compose;
use crate::topology::{Assembly, AssemblyId, Instance, Model, Part, ShellId, SolidId};

/// The part each member entity became, by id: a face in a shell becomes its shell (or that
/// shell's solid), as sewing put it there.
fn parts(topology: &Topology) -> HashMap<&str, Part> {
    let m = &topology.model;
    let mut solid_of: HashMap<usize, usize> = HashMap::new();
    for (i, s) in m.solids.iter().enumerate() {
        for sh in std::iter::once(&s.outer).chain(&s.voids) {
            solid_of.insert(sh.0, i);
        }
    }
    let mut shell_of: HashMap<usize, usize> = HashMap::new();
    for (i, s) in m.shells.iter().enumerate() {
        for (f, _) in &s.faces {
            shell_of.entry(f.0).or_insert(i);
        }
    }
    let shell_part = |s: usize| {
        solid_of
            .get(&s)
            .map_or(Part::Shell(ShellId(s)), |&i| Part::Solid(SolidId(i)))
    };
    let mut out = parts_by_id(&topology.origins);
    for p in out.values_mut() {
        *p = match *p {
            Part::Shell(s) => shell_part(s.0),
            Part::Face(f) => shell_of.get(&f.0).map_or(Part::Face(f), |&s| shell_part(s)),
            other => other,
        };
    }
    out
}

/// The 408's placement in the document's unit (see the module documentation), or `None`
/// with a diagnostic.
fn placement(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    rec: &SubfigureInstance408,
    diags: &mut Vec<Diagnostic>,
) -> Option<[[f64; 4]; 3]> {
    let (s, t) = (rec.scale, rec.translation);
    let local = [
        [s, 0.0, 0.0, t[0]],
        [0.0, s, 0.0, t[1]],
        [0.0, 0.0, s, t[2]],
    ];
    let m = match cx.transforms(entry, &mut Meta::default(), diags)? {
        Some(m) => compose(&m, &local),
        None => local,
    };
    // Lengths in the file's unit scaled to the document's: the translation only.
    let f = cx.factor.unwrap_or(1.0);
    Some(m.map(|r| [r[0], r[1], r[2], r[3] * f]))
}

/// Reads the file's 308/408 subfigures and applies their placements to `topology`.
pub(super) fn apply(cx: &Context<'_, '_>, topology: &mut Topology, diags: &mut Vec<Diagnostic>) {
    let entries: Vec<&DirectoryEntry> = cx
        .file
        .entries
        .iter()
        .flatten()
        .filter(|e| matches!(e.entity_type, 308 | 408))
        .collect();
    let definitions: Vec<&DirectoryEntry> = entries
        .iter()
        .copied()
        .filter(|e| e.entity_type == 308)
        .collect();
    if definitions.is_empty() {
        return;
    }
    // Assembly 0 is the file (the root); then one per 308.
    let index: HashMap<usize, usize> = definitions
        .iter()
        .enumerate()
        .map(|(i, e)| (e.pointer, i + 1))
        .collect();
    let mut model = Model::default();
    let mut ids = vec!["file".to_owned()];
    let mut sources: Vec<Vec<String>> = vec![Vec::new()];
    model.add_assembly(Assembly {
        name: "file".to_owned(),
        instances: Vec::new(),
    });
    let by_id = parts(topology);
    let mut nested: HashSet<usize> = HashSet::new();
    let mut not_placed = 0usize;
    let instance = |e: &DirectoryEntry, diags: &mut Vec<Diagnostic>| -> Option<Instance> {
        let rec = decoded(cx.file.decode::<SubfigureInstance408>(e), diags)?;
        let Some(&def) = usize::try_from(rec.definition)
            .ok()
            .and_then(|d| index.get(&d))
        else {
            diags.push(Diagnostic::error(
                "assembly.not_placed",
                format!(
                    "408 D{} names D{}, which is not a 308 subfigure definition; the instance is not placed",
                    e.pointer, rec.definition
                ),
                entity_location(e),
            ));
            return None;
        };
        let placement = placement(cx, e, &rec, diags)?;
        let label = e.label.trim();
        Some(Instance {
            name: Some(if label.is_empty() {
                format!("D{}", e.pointer)
            } else if e.subscript != 0 {
                format!("{label}.{}", e.subscript)
            } else {
                label.to_owned()
            }),
            placement,
            part: Part::Assembly(AssemblyId(def)),
        })
    };
    for d in &definitions {
        let Some(rec) = decoded(cx.file.decode::<SubfigureDefinition308>(d), diags) else {
            model.add_assembly(Assembly {
                name: format!("D{}", d.pointer),
                instances: Vec::new(),
            });
            ids.push(format!("D{}", d.pointer));
            sources.push(Vec::new());
            continue;
        };
        let mut instances = Vec::new();
        let mut src = Vec::new();
        let mut seen: HashSet<Part> = HashSet::new();
        for &m in &rec.members {
            let Some(member) = cx.file.entry(m) else {
                continue;
            };
            if member.entity_type == 408 {
                nested.insert(member.pointer);
                if let Some(i) = instance(member, diags) {
                    instances.push(i);
                    src.push(format!("D{}", member.pointer));
                }
                continue;
            }
            match by_id.get(format!("D{}", member.pointer).as_str()).copied() {
                Some(p) if seen.insert(p) => {
                    instances.push(Instance {
                        name: None,
                        placement: crate::nurbs::transform::IDENTITY,
                        part: p,
                    });
                    src.push(String::new());
                }
                Some(_) => {}
                None => not_placed += 1,
            }
        }
        model.add_assembly(Assembly {
            name: rec
                .name
                .filter(|n| !n.is_empty())
                .unwrap_or_else(|| format!("D{}", d.pointer)),
            instances,
        });
        ids.push(format!("D{}", d.pointer));
        sources.push(src);
    }
    for e in entries.iter().filter(|e| e.entity_type == 408) {
        if nested.contains(&e.pointer) {
            continue;
        }
        if let Some(i) = instance(e, diags) {
            model.assemblies[0].instances.push(i);
            sources[0].push(format!("D{}", e.pointer));
        }
    }
    if not_placed > 0 {
        diags.push(Diagnostic::warning(
            "assembly.geometry_not_placed",
            format!("{not_placed} member(s) of 308 subfigure definitions are not faces, shells or solids (free curves and surfaces): kept once, where the definition places them"),
            Location::default(),
        )
        .not_carried());
    }
    let defs = Definitions {
        model,
        ids,
        sources,
    };
    let locate = |id: &str| {
        id.strip_prefix('D')
            .and_then(|d| d.parse::<i64>().ok())
            .and_then(|d| cx.file.entry(d))
            .map_or_else(Location::default, entity_location)
    };
    diags.extend(place_all(
        &defs,
        topology,
        cx.options.limits.max_entities,
        &locate,
    ));
}
