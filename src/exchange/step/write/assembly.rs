//! A document's product structure -> STEP: the assembly structure of ISO 10303-44 as AP214
//! (and AP203, AP242) files carry it and Open CASCADE writes it.
//!
//! - Every product (each [`Assembly`] of the structure reached from a root) is a PRODUCT
//!   with its PRODUCT_DEFINITION_FORMATION, PRODUCT_DEFINITION, PRODUCT_DEFINITION_SHAPE and
//!   a SHAPE_DEFINITION_REPRESENTATION naming its shape representation, which holds the
//!   product's own solids (MANIFOLD_SOLID_BREP), shells and faces (one
//!   SHELL_BASED_SURFACE_MODEL) and, in a root, free curves (GEOMETRIC_CURVE_SET). Every
//!   part's geometry is written once (`write/topology.rs` over the structure's model).
//! - Every instance of a product in another is a NEXT_ASSEMBLY_USAGE_OCCURRENCE (relating:
//!   the assembly, related: the component) whose PRODUCT_DEFINITION_SHAPE a
//!   CONTEXT_DEPENDENT_SHAPE_REPRESENTATION joins to a REPRESENTATION_RELATIONSHIP_WITH_
//!   TRANSFORMATION (with SHAPE_REPRESENTATION_RELATIONSHIP, a complex instance) from the
//!   component's representation (`rep_1`) to the assembly's (`rep_2`). Its
//!   ITEM_DEFINED_TRANSFORMATION maps the component's placement at the origin
//!   (`transform_item_1`) onto an AXIS2_PLACEMENT_3D among the assembly's items
//!   (`transform_item_2`): with `A(p)` the matrix of axis placement `p` (ISO 10303-42
//!   `build_axes`), a component point `x` goes to `A(item_2) A(item_1)^-1 x = A(item_2) x`
//!   (ISO 10303-43 item_defined_transformation).
//! - An axis placement is a rotation and a translation: an instance whose placement also
//!   scales, shears or mirrors has no AXIS2_PLACEMENT_3D pair, so its parts are written
//!   placed into the assembly's coordinates, as part of the assembly's own shape (the
//!   instance and its product are not written; a warning says so).

use std::borrow::Cow;

use nurbsx_parsers::real::NonFiniteReal;
use nurbsx_parsers::step::{Body, Parameter, Record};

use super::topology::{Out, representation, surface_model, write_free, write_model};
use super::{ProductIds, assemble, finish, frame, geometric_set, real_error, rec, s};
use crate::exchange::assembly::{MAX_DEPTH, MAX_INSTANCES};
use crate::exchange::step::geometry::axes_as_read;
use crate::exchange::{Diagnostic, Document, ExportOptions, Location, Origins};
use crate::nurbs::Point3;
use crate::nurbs::transform::{Affine, IDENTITY, compose};
use crate::topology::{Assembly, Model, Part};

/// Largest deviation of `R^T R` from the identity for which a placement's linear part `R`
/// is taken for a rotation: an AXIS2_PLACEMENT_3D carries `R`'s third and first columns,
/// from which a reader rebuilds `R` (ISO 10303-42 `build_axes`) to within this, so a
/// written part point `x` moves by at most about `1e-12 |x|`.
pub(crate) const RIGID: f64 = 1e-12;

/// Why `m` is not a rigid motion (rotation and translation), if it is not.
pub(crate) fn not_rigid(m: &Affine) -> Option<String> {
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Some("it is not finite".to_owned());
    }
    let column = |c: usize| [m[0][c], m[1][c], m[2][c]];
    let mut worst = 0.0f64;
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) = (column(i), column(j));
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            worst = worst.max((dot - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    if worst > RIGID {
        return Some(format!(
            "its linear part scales or shears (R^T R differs from the identity by {worst:.3e})"
        ));
    }
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    (det <= 0.0).then(|| "it mirrors (its linear part has a negative determinant)".to_owned())
}

/// `x` moved by `k` units in the last place (zero stays zero).
fn ulps(x: f64, k: i64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let bits = i64::try_from(x.abs().to_bits()).unwrap_or(i64::MAX);
    let moved = f64::from_bits(u64::try_from(bits.saturating_add(k).max(1)).unwrap_or(1));
    if x < 0.0 { -moved } else { moved }
}

/// The vectors whose components are those of `v` moved by at most 2 units in the last
/// place, `v` itself first.
fn near(v: Point3) -> impl Iterator<Item = Point3> {
    const STEPS: [i64; 5] = [0, -1, 1, -2, 2];
    STEPS.into_iter().flat_map(move |a| {
        STEPS.into_iter().flat_map(move |b| {
            STEPS
                .into_iter()
                .map(move |c| [ulps(v[0], a), ulps(v[1], b), ulps(v[2], c)])
        })
    })
}

/// The axis and ref_direction written for the rotation of `m`: its third and first
/// columns, or, when a reader would rebuild other axes from those (`axes_as_read`
/// normalises each direction and builds the axes, ISO 10303-42 `build_axes`, each step
/// rounding), the nearest directions (within 2 units in the last place of each component)
/// from which it rebuilds exactly the held axes. A placement that was read from a STEP
/// file is one such rebuild, so it always has one: written again, it reads back bit for
/// bit, and STEP -> STEP -> STEP keeps the placed geometry.
fn exact_axes(m: &Affine) -> (Point3, Point3) {
    let column = |c: usize| [m[0][c], m[1][c], m[2][c]];
    let (x0, y0, z0) = (column(0), column(1), column(2));
    let exact = |z: Point3, x: Point3| {
        axes_as_read(z, x).is_some_and(|f| f.x == x0 && f.y == y0 && f.z == z0)
    };
    if exact(z0, x0) {
        return (z0, x0);
    }
    // The rebuilt z depends on the axis only.
    let z = near(z0)
        .find(|z| axes_as_read(*z, x0).is_some_and(|f| f.z == z0))
        .unwrap_or(z0);
    let x = near(x0).find(|x| exact(z, *x)).unwrap_or(x0);
    (z, x)
}

/// How the STEP writer writes a document's assembly, and what the user should know.
pub(crate) struct Plan<'d> {
    /// The product structure to write; `None`: the flattened model is written.
    pub structure: Option<Structured<'d>>,
    /// The instances written flattened and why, or why the whole assembly is.
    pub diagnostics: Vec<Diagnostic>,
}

/// One instance of a product in another.
pub(crate) struct Usage {
    name: String,
    placement: Affine,
    product: usize,
}

/// The product structure as it is written.
pub(crate) struct Structured<'d> {
    /// The structure's model, with the copies of the instances written flattened appended.
    model: Cow<'d, Model>,
    origins: &'d Origins,
    /// The products written (assembly indices), roots first.
    products: Vec<usize>,
    /// Per assembly: its own parts.
    own: Vec<Vec<Part>>,
    /// Per assembly: its instances of other products.
    usages: Vec<Vec<Usage>>,
}

/// The whole assembly written flattened, saying why (`requested`: an info).
fn flattened(document: &Document, why: &str, requested: bool) -> Plan<'static> {
    let m = &document.topology.model;
    let message = format!(
        "assembly written flattened ({why}): {} instance(s) written as their placed solids, shells and faces in root coordinates ({} solid(s), {} face(s)); the product structure (products, instances and their names) is not written",
        document.topology.instances.len(),
        m.solids.len(),
        m.faces.len()
    );
    Plan {
        structure: None,
        diagnostics: vec![if requested {
            Diagnostic::info("assembly.flattened", message, Location::default())
        } else {
            Diagnostic::warning("assembly.flattened", message, Location::default())
        }],
    }
}

/// Decides how `document`'s assembly is written (module documentation). Without instances
/// there is nothing to say; the structure is refused whole (and the flattened model
/// written) when the options ask for it, when the document has none, when its tree does not
/// expand (a cycle, a missing assembly or part, beyond the read limits) or when a product
/// that is not a root holds free curves (a GEOMETRIC_CURVE_SET in a product's shape is not
/// placed by every reader).
pub(crate) fn plan<'d>(document: &'d Document, options: &ExportOptions) -> Plan<'d> {
    let topology = &document.topology;
    if topology.instances.is_empty() && topology.structure.is_none() {
        return Plan {
            structure: None,
            diagnostics: Vec::new(),
        };
    }
    if options.flatten_assemblies {
        return flattened(document, "as requested", true);
    }
    let Some(structure) = topology.structure.as_deref() else {
        return flattened(document, "the document holds no product structure", false);
    };
    let source = &structure.model;
    for root in &structure.roots {
        if let Err(e) = source.flatten(*root, MAX_DEPTH, MAX_INSTANCES) {
            return flattened(document, &e.to_string(), false);
        }
    }
    let n = source.assemblies.len();
    let mut model: Cow<'d, Model> = Cow::Borrowed(source);
    let mut own: Vec<Vec<Part>> = vec![Vec::new(); n];
    let mut usages: Vec<Vec<Usage>> = (0..n).map(|_| Vec::new()).collect();
    let mut products: Vec<usize> = Vec::new();
    let mut seen = vec![false; n];
    let mut diagnostics = Vec::new();
    let mut stack: Vec<usize> = structure.roots.iter().rev().map(|r| r.0).collect();
    while let Some(a) = stack.pop() {
        if std::mem::replace(&mut seen[a], true) {
            continue;
        }
        products.push(a);
        let assembly: &Assembly = &source.assemblies[a];
        let mut children = Vec::new();
        for (i, inst) in assembly.instances.iter().enumerate() {
            // What is placed into this product's own shape: (part, placement) pairs.
            let mut copies: Vec<(Part, Affine)> = Vec::new();
            match inst.part {
                Part::Assembly(c) => match not_rigid(&inst.placement) {
                    None => {
                        let product = source.assemblies[c.0].name.clone();
                        usages[a].push(Usage {
                            name: inst
                                .name
                                .clone()
                                .unwrap_or_else(|| format!("{product}_{}", i + 1)),
                            placement: inst.placement,
                            product: c.0,
                        });
                        children.push(c.0);
                    }
                    Some(why) => {
                        let leaves = match source.flatten(c, MAX_DEPTH, MAX_INSTANCES) {
                            Ok(l) => l,
                            Err(e) => return flattened(document, &e.to_string(), false),
                        };
                        diagnostics.push(Diagnostic::warning(
                            "assembly.instance_flattened",
                            format!(
                                "instance '{}' of '{}' in '{}' written flattened: {why}, which an AXIS2_PLACEMENT_3D cannot express; its {} part(s) are written placed into '{}' coordinates, as part of its own shape, without the instance and its product",
                                inst.name.as_deref().unwrap_or("(unnamed)"),
                                source.assemblies[c.0].name,
                                assembly.name,
                                leaves.len(),
                                assembly.name
                            ),
                            Location::default(),
                        ));
                        copies.extend(
                            leaves
                                .into_iter()
                                .map(|l| (l.part, compose(&inst.placement, &l.placement))),
                        );
                    }
                },
                part if inst.placement == IDENTITY => {
                    if let Err(e) = source.part_size(part) {
                        return flattened(document, &e.to_string(), false);
                    }
                    own[a].push(part);
                }
                part => copies.push((part, inst.placement)),
            }
            for (part, placement) in copies {
                let target = model.to_mut();
                match source.place(part, &placement, target) {
                    Ok((placed, _)) => own[a].push(placed),
                    Err(e) => return flattened(document, &e.to_string(), false),
                }
            }
        }
        stack.extend(children.into_iter().rev());
    }
    let roots: Vec<usize> = structure.roots.iter().map(|r| r.0).collect();
    if let Some(&a) = products
        .iter()
        .find(|&&a| !roots.contains(&a) && own[a].iter().any(|p| matches!(p, Part::Edge(_))))
    {
        let why = format!(
            "product '{}' holds free curves, which a GEOMETRIC_CURVE_SET in its shape would leave unplaced for some readers",
            source.assemblies[a].name
        );
        return flattened(document, &why, false);
    }
    Plan {
        structure: Some(Structured {
            model,
            origins: &structure.origins,
            products,
            own,
            usages,
        }),
        diagnostics,
    }
}

/// The warnings (and on request the info) about how the STEP writer writes `document`'s
/// assembly, without writing it: [`write_reporting`](super::write_reporting) returns the
/// same with the text it writes.
pub fn assembly_warnings(document: &Document, options: &ExportOptions) -> Vec<Diagnostic> {
    plan(document, options).diagnostics
}

/// One product's shape items: solids and surface models (as [`representation`] takes
/// them) and free curves.
struct Shape {
    items: Vec<(&'static str, u64)>,
    curves: Vec<u64>,
}

/// Writes `document` with its product structure `plan` (module documentation).
pub(super) fn write(
    document: &Document,
    options: &ExportOptions,
    plan: &Structured<'_>,
) -> Result<String, Diagnostic> {
    let assemblies = &plan.model.assemblies;
    let name = |a: usize| assemblies.get(a).map_or("", |x| x.name.as_str());
    let first_product = plan.products.first().copied().unwrap_or(0);
    let mut f = frame(document, options, Some(name(first_product)));
    let first = f.b.next_id();
    let scale = f.scale;
    let mut w = Out {
        text: String::new(),
        id: first,
    };
    // The shape items of each product: (kind, id) as `representation` takes them.
    let body = (|| -> Result<_, NonFiniteReal> {
        let free = write_free(&mut w, document, &plan.model, plan.origins, scale, options)?;
        let written = write_model(&mut w, document, &plan.model, plan.origins, scale, options)?;
        let mut shapes: Vec<Shape> = Vec::new();
        for &a in &plan.products {
            let mut items = Vec::new();
            let (mut shells, mut faces, mut curves) = (Vec::new(), Vec::new(), Vec::new());
            let mut listed = std::collections::HashSet::new();
            for part in &plan.own[a] {
                match *part {
                    Part::Solid(x) => {
                        if let Some(Some(id)) = written.solids.get(x.0) {
                            items.push(("solid", *id));
                        }
                    }
                    Part::Shell(x) => shells.extend(written.shells.get(x.0).copied().flatten()),
                    Part::Face(x) => faces.extend(written.faces.get(x.0)),
                    // A curve several free edges share is listed once.
                    Part::Edge(x) => {
                        curves.extend(written.curves.get(x.0).filter(|c| listed.insert(**c)))
                    }
                    Part::Assembly(_) => {}
                }
            }
            surface_model(&mut w, shells, &faces, &mut items)?;
            shapes.push(Shape { items, curves });
        }
        Ok((shapes, free))
    })();
    let (shapes, free) = body.map_err(real_error)?;
    f.b.reserve_many(w.id - first);

    // The products after the first: their chains, with their representations' ids.
    let mut ids: Vec<(u64, u64)> = vec![(0, 0); assemblies.len()]; // (definition, representation)
    if let Some(x) = ids.get_mut(first_product) {
        *x = (f.definition, f.rep);
    }
    for &a in plan.products.iter().skip(1) {
        let chain = ProductIds {
            sdr: f.b.reserve(),
            pds: f.b.reserve(),
            pd: f.b.reserve(),
            pdf: f.b.reserve(),
            product: f.b.reserve(),
            rep: f.b.reserve(),
        };
        super::product_chain(&mut f.b, &chain, f.products, name(a));
        ids[a] = (chain.pd, chain.rep);
    }
    // The instances, each with its placement among its assembly's items.
    let mut placements: Vec<Vec<u64>> = vec![Vec::new(); assemblies.len()];
    let mut count = 0i64;
    for &a in &plan.products {
        for u in &plan.usages[a] {
            count += 1;
            let m = &u.placement;
            let (z, x) = exact_axes(m);
            let origin = f.b.simple(
                "CARTESIAN_POINT",
                vec![
                    s(""),
                    Parameter::reals(&[m[0][3] * scale, m[1][3] * scale, m[2][3] * scale]),
                ],
            );
            let axis = f.b.simple("DIRECTION", vec![s(""), Parameter::reals(&z)]);
            let reference = f.b.simple("DIRECTION", vec![s(""), Parameter::reals(&x)]);
            let target = f.b.simple(
                "AXIS2_PLACEMENT_3D",
                vec![
                    s(""),
                    Parameter::Reference(origin),
                    Parameter::Reference(axis),
                    Parameter::Reference(reference),
                ],
            );
            placements[a].push(target);
            let transformation = f.b.simple(
                "ITEM_DEFINED_TRANSFORMATION",
                vec![
                    s(""),
                    s(""),
                    Parameter::Reference(f.placement),
                    Parameter::Reference(target),
                ],
            );
            let relation = f.b.complex(vec![
                rec(
                    "REPRESENTATION_RELATIONSHIP",
                    vec![
                        s(""),
                        s(""),
                        Parameter::Reference(ids[u.product].1),
                        Parameter::Reference(ids[a].1),
                    ],
                ),
                rec(
                    "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
                    vec![Parameter::Reference(transformation)],
                ),
                rec("SHAPE_REPRESENTATION_RELATIONSHIP", vec![]),
            ]);
            let usage = f.b.simple(
                "NEXT_ASSEMBLY_USAGE_OCCURRENCE",
                vec![
                    s(&count.to_string()),
                    s(&u.name),
                    s(""),
                    Parameter::Reference(ids[a].0),
                    Parameter::Reference(ids[u.product].0),
                    Parameter::Null,
                ],
            );
            let shape = f.b.simple(
                "PRODUCT_DEFINITION_SHAPE",
                vec![
                    s("Placement"),
                    s("Placement of an item"),
                    Parameter::Reference(usage),
                ],
            );
            f.b.simple(
                "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
                vec![Parameter::Reference(relation), Parameter::Reference(shape)],
            );
        }
    }
    // The representations: the first product's also holds the free geometry.
    let mut header = Vec::new();
    for (k, (&a, Shape { items, curves })) in plan.products.iter().zip(&shapes).enumerate() {
        let (set, set_keyword) = if k == 0 {
            let mut all = free.curves3.clone();
            all.extend(curves);
            geometric_set(&mut f.b, &all, &free.surfaces)
        } else {
            geometric_set(&mut f.b, curves, &[])
        };
        let mut keyword = representation(items, set.is_some(), set_keyword);
        if set.is_none() && items.is_empty() {
            keyword = "SHAPE_REPRESENTATION";
        }
        let mut refs: Vec<u64> = items.iter().map(|(_, id)| *id).collect();
        refs.extend(set);
        refs.extend(&placements[a]);
        if k == 0 {
            header = finish(&mut f, options, keyword, &refs, &free.curves2);
        } else {
            let mut all = vec![f.placement];
            all.extend(refs);
            f.b.set(
                ids[a].1,
                Body::Simple(Record {
                    keyword,
                    params: vec![s(""), Parameter::refs(&all), Parameter::Reference(f.ctx3)],
                }),
            );
        }
    }
    let size = w.text.len() + 4096;
    assemble(&mut f, &header, first, size, |out| {
        out.push_str(&w.text);
        Ok(())
    })
}
