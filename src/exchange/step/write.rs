//! [`Document`] -> STEP file that Open CASCADE / FreeCAD imports (spec.md c.4, c.5).
//!
//! Layout: the product chain Open CASCADE writes (APPLICATION_PROTOCOL_DEFINITION ...
//! SHAPE_DEFINITION_REPRESENTATION), one representation context with the length unit and
//! uncertainty, then
//! - 3-D curves only: `GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION` with a
//!   `GEOMETRIC_CURVE_SET` listing the B-splines (each becomes an edge on import);
//! - surfaces (and any 3-D curves with them):
//!   `GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION` with a `GEOMETRIC_SET` (each
//!   bounded surface becomes a face, each curve an edge);
//! - a document with topology: its faces, shells and solids (write/topology.rs), then its
//!   free curves and surfaces;
//! - a document with an assembly's product structure: one product per assembly and part,
//!   each part's geometry once, placed by its instances (write/assembly.rs);
//! - 2-D curves (pcurves): a separate wireframe representation in a 2-D context, not
//!   attached to the product (a 2-D curve has no place in a 3-D shape; nurbsx reads it back,
//!   Open CASCADE ignores it).
//!
//! Polynomial B-splines are simple `B_SPLINE_CURVE_WITH_KNOTS` / `..._SURFACE_WITH_KNOTS`
//! instances; rational ones the seven-partial complex instance in alphabetical order.
//! Knots are written exactly as held (unclamped and periodic data stays as is); `knot_spec`
//! is computed from the knots ([`knot_form`]). With
//! [`ExportOptions::use_implicit_knot_subtypes`], knots equal to those a BEZIER_/UNIFORM_/
//! QUASI_UNIFORM_ subtype implies are written as that subtype, except where Open CASCADE
//! would drop or misread it (rational or multi-span Bezier): those keep explicit knots.

use std::borrow::Cow;

use nurbsx_parsers::real::NonFiniteReal;
use nurbsx_parsers::step::schema::{
    BSplineCurve, BSplineSurface, CartesianPoint, KnotSpec, PerDirection,
};
use nurbsx_parsers::step::writer::{
    write_bspline_curve, write_bspline_surface, write_cartesian_point, write_instance, write_record,
};
use nurbsx_parsers::step::{Body, Builder, Parameter, Record, StepString};

use super::closure_tolerance;
use super::implicit::{KnotForm, implicit_knots, knot_form};
use crate::exchange::{
    Diagnostic, Document, Entity, ExportOptions, LengthUnit, Location, ParameterRange, Shape,
    StepSchema,
};
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, distance};

mod assembly;
mod topology;

pub use assembly::assembly_warnings;

/// Schema-dependent strings of the product chain (as Open CASCADE 7.6 writes them).
struct Protocol {
    file_schema: &'static str,
    apd_name: &'static str,
    apd_year: i64,
    context: &'static str,
}

fn protocol(schema: StepSchema) -> Protocol {
    match schema {
        StepSchema::Ap214 => Protocol {
            file_schema: "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }",
            apd_name: "automotive_design",
            apd_year: 2000,
            context: "core data for automotive mechanical design processes",
        },
        StepSchema::Ap203 => Protocol {
            file_schema: "CONFIG_CONTROL_DESIGN",
            apd_name: "config_control_design",
            apd_year: 1994,
            context: "configuration controlled 3D designs of mechanical parts and assemblies",
        },
        StepSchema::Ap242 => Protocol {
            file_schema: "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF { 1 0 10303 442 1 1 4 }",
            apd_name: "ap242_managed_model_based_3d_engineering",
            apd_year: 2013,
            context: "Managed model based 3d engineering",
        },
    }
}

fn s(text: &str) -> Parameter<'static> {
    Parameter::text(text)
}

fn rec(keyword: &'static str, params: Vec<Parameter<'static>>) -> Record<'static> {
    Record { keyword, params }
}
/// Everything before the geometry: the product chain, the 3-D context and the placement.
struct Frame {
    b: Builder,
    unit: LengthUnit,
    scale: f64,
    /// The length uncertainty declared in the contexts (output unit).
    uncertainty: f64,
    proto: Protocol,
    name: String,
    rep: u64,
    ctx3: u64,
    placement: u64,
    /// The contexts more products name (an assembly's).
    products: ProductContexts,
    /// The first product's definition.
    definition: u64,
}

/// The contexts every product of a file shares.
#[derive(Clone, Copy)]
struct ProductContexts {
    product: u64,
    definition: u64,
    ap203: bool,
}

/// The ids of one product's chain (ISO 10303-41 product, product_definition_formation,
/// product_definition; ISO 10303-41 product_definition_shape and
/// shape_definition_representation naming the shape `rep`).
struct ProductIds {
    sdr: u64,
    pds: u64,
    pd: u64,
    pdf: u64,
    product: u64,
    rep: u64,
}

/// Writes a product chain named `name` (reserved ids `ids`) with its category.
fn product_chain(b: &mut Builder, ids: &ProductIds, cx: ProductContexts, name: &str) {
    b.set(
        ids.sdr,
        Body::Simple(rec(
            "SHAPE_DEFINITION_REPRESENTATION",
            vec![Parameter::Reference(ids.pds), Parameter::Reference(ids.rep)],
        )),
    );
    b.set(
        ids.pds,
        Body::Simple(rec(
            "PRODUCT_DEFINITION_SHAPE",
            vec![s(""), s(""), Parameter::Reference(ids.pd)],
        )),
    );
    b.set(
        ids.pd,
        Body::Simple(rec(
            "PRODUCT_DEFINITION",
            vec![
                s("design"),
                s(""),
                Parameter::Reference(ids.pdf),
                Parameter::Reference(cx.definition),
            ],
        )),
    );
    b.set(
        ids.pdf,
        Body::Simple(if cx.ap203 {
            rec(
                "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE",
                vec![
                    s(""),
                    s(""),
                    Parameter::Reference(ids.product),
                    Parameter::Enumeration("NOT_KNOWN"),
                ],
            )
        } else {
            rec(
                "PRODUCT_DEFINITION_FORMATION",
                vec![s(""), s(""), Parameter::Reference(ids.product)],
            )
        }),
    );
    b.set(
        ids.product,
        Body::Simple(rec(
            "PRODUCT",
            vec![s(name), s(name), s(""), Parameter::refs(&[cx.product])],
        )),
    );
    b.simple(
        "PRODUCT_RELATED_PRODUCT_CATEGORY",
        vec![s("part"), Parameter::Null, Parameter::refs(&[ids.product])],
    );
}

/// The instances every file starts with (ids `#1`.. in the order Open CASCADE writes them),
/// the first product named `product` (the file name when `None`).
fn frame(document: &Document, options: &ExportOptions, product: Option<&str>) -> Frame {
    let unit = options.units.unwrap_or(document.units);
    let scale = if unit == document.units {
        1.0
    } else {
        document.units.to_mm() / unit.to_mm()
    };
    let proto = protocol(options.schema);
    let mut b = Builder::new();
    let apd = b.reserve();
    let app = b.reserve();
    let sdr = b.reserve();
    let pds = b.reserve();
    let pd = b.reserve();
    let pdf = b.reserve();
    let product_id = b.reserve();
    let pc = b.reserve();
    let pdc = b.reserve();
    let rep = b.reserve();
    b.set(
        apd,
        Body::Simple(rec(
            "APPLICATION_PROTOCOL_DEFINITION",
            vec![
                s("international standard"),
                s(proto.apd_name),
                Parameter::Integer(proto.apd_year),
                Parameter::Reference(app),
            ],
        )),
    );
    b.set(
        app,
        Body::Simple(rec("APPLICATION_CONTEXT", vec![s(proto.context)])),
    );
    let ap203 = options.schema == StepSchema::Ap203;
    let name = if options.file_name.is_empty() {
        "nurbsx"
    } else {
        options.file_name.as_str()
    };
    let contexts = ProductContexts {
        product: pc,
        definition: pdc,
        ap203,
    };
    let ids = ProductIds {
        sdr,
        pds,
        pd,
        pdf,
        product: product_id,
        rep,
    };
    product_chain(&mut b, &ids, contexts, product.unwrap_or(name));
    b.set(
        pc,
        Body::Simple(rec(
            if ap203 {
                "MECHANICAL_CONTEXT"
            } else {
                "PRODUCT_CONTEXT"
            },
            vec![s(""), Parameter::Reference(app), s("mechanical")],
        )),
    );
    b.set(
        pdc,
        Body::Simple(if ap203 {
            rec(
                "DESIGN_CONTEXT",
                vec![s(""), Parameter::Reference(app), s("design")],
            )
        } else {
            rec(
                "PRODUCT_DEFINITION_CONTEXT",
                vec![s("part definition"), Parameter::Reference(app), s("design")],
            )
        }),
    );

    // 1e-7 as Open CASCADE writes, or the model's own tolerance when larger (a part sewn
    // within a user's tolerance), so that a reader joins what the model joins.
    let uncertainty = (document.topology.model.max_tolerance() * scale).max(1e-7);
    let ctx3 = context(&mut b, unit, 3, uncertainty);
    let placement = axis_placement(&mut b);
    Frame {
        b,
        unit,
        scale,
        uncertainty,
        proto,
        name: name.to_owned(),
        rep,
        ctx3,
        placement,
        products: contexts,
        definition: pd,
    }
}

/// The set holding the free 3-D curves and surfaces (`None` when there are none:
/// GEOMETRIC_SET / GEOMETRIC_CURVE_SET need at least one element, SET [1:?]) and the
/// representation that holds only such geometry.
fn geometric_set(
    b: &mut Builder,
    curves3: &[u64],
    surfaces: &[u64],
) -> (Option<u64>, &'static str) {
    if surfaces.is_empty() {
        let set = (!curves3.is_empty())
            .then(|| b.simple("GEOMETRIC_CURVE_SET", vec![s(""), Parameter::refs(curves3)]));
        (set, "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION")
    } else {
        let mut members = curves3.to_vec();
        members.extend(surfaces);
        let set = b.simple("GEOMETRIC_SET", vec![s(""), Parameter::refs(&members)]);
        (
            Some(set),
            "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
        )
    }
}

/// The instances after the geometry (the shape representation with `items` after the
/// placement, the 2-D curves' representation) and the header records.
fn finish(
    f: &mut Frame,
    options: &ExportOptions,
    rep_keyword: &'static str,
    shape_items: &[u64],
    curves2: &[u64],
) -> Vec<Record<'static>> {
    let (b, unit, uncertainty, proto, name, rep, ctx3, placement) = (
        &mut f.b,
        f.unit,
        f.uncertainty,
        &f.proto,
        f.name.as_str(),
        f.rep,
        f.ctx3,
        f.placement,
    );
    // A document without 3-D geometry gets a representation holding only its placement.
    let mut items = vec![placement];
    items.extend_from_slice(shape_items);
    b.set(
        rep,
        Body::Simple(rec(
            rep_keyword,
            vec![s(""), Parameter::refs(&items), Parameter::Reference(ctx3)],
        )),
    );
    if !curves2.is_empty() {
        let ctx2 = context(b, unit, 2, uncertainty);
        let set = b.simple("GEOMETRIC_CURVE_SET", vec![s(""), Parameter::refs(curves2)]);
        b.simple(
            "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
            vec![
                s("2D curves"),
                Parameter::refs(&[set]),
                Parameter::Reference(ctx2),
            ],
        );
    }

    let timestamp = options.timestamp.clone().unwrap_or_else(now_iso8601);
    vec![
        rec(
            "FILE_DESCRIPTION",
            vec![Parameter::List(vec![s("nurbsx model")]), s("2;1")],
        ),
        rec(
            "FILE_NAME",
            vec![
                s(name),
                s(&timestamp),
                Parameter::List(vec![s("")]),
                Parameter::List(vec![s("")]),
                s(concat!("nurbsx ", env!("CARGO_PKG_VERSION"))),
                s("nurbsx"),
                s(""),
            ],
        ),
        rec(
            "FILE_SCHEMA",
            vec![Parameter::List(vec![s(proto.file_schema)])],
        ),
    ]
}

/// Writes a document as a STEP file (module documentation above). Coordinates are scaled
/// once when `options.units` differs from the document's unit; the file declares the unit
/// its numbers are in. Fails on non-finite values (impossible for checked NURBS) only.
///
/// The geometry (poles and B-spline instances, nearly all of a file) becomes typed records
/// (`CartesianPoint`, `BSplineCurve`, `BSplineSurface`) that the Part 21 record writers
/// append to one pre-sized string, with no parameter tree; the few other instances go
/// through [`Builder`] and [`write_instance`]. The text is byte-identical to the
/// parameter-tree path (the reference writer of the tests) and ids are assigned in the same
/// order: each entity's poles, then the entity.
///
/// What the writer says about the file (how it wrote an assembly) is left out: see
/// [`write_reporting`].
pub fn write(document: &Document, options: &ExportOptions) -> Result<String, Diagnostic> {
    write_reporting(document, options).map(|(text, _)| text)
}

/// Writes `document` as [`write()`] does, and returns with the text what the writer says
/// about it: how it wrote the document's assembly (the instances written flattened and
/// why, or why the whole assembly is; on request an info), from the one assembly plan the
/// writing follows ([`assembly_warnings`] gives the same without writing).
pub fn write_reporting(
    document: &Document,
    options: &ExportOptions,
) -> Result<(String, Vec<Diagnostic>), Diagnostic> {
    if !document.topology.is_empty() {
        return topology::write(document, options);
    }
    let mut f = frame(document, options, None);
    let first = f.b.next_id();
    let mut next = first;
    let mut size = 16_384usize;
    let (mut curves3, mut curves2, mut surfaces) = (Vec::new(), Vec::new(), Vec::new());
    let range_error = |e: &Entity| {
        Diagnostic::error(
            "step.write",
            "degree out of range",
            Location::at_entity(e.id.clone()),
        )
    };
    for e in &document.entities {
        // Ids as the reference path creates them: the poles, then the entity.
        let (poles, reals) = match &e.geometry {
            Geometry::Curve(c) => {
                i64::try_from(c.degree()).map_err(|_| range_error(e))?;
                (c.num_poles(), c.knots().len() + c.num_poles())
            }
            Geometry::Surface(sf) => {
                i64::try_from(sf.degree_u()).map_err(|_| range_error(e))?;
                i64::try_from(sf.degree_v()).map_err(|_| range_error(e))?;
                let n = sf.control_points().as_slice().len();
                (n, sf.knots_u().len() + sf.knots_v().len() + n)
            }
        };
        let id = next.saturating_add(u64::try_from(poles).unwrap_or(u64::MAX));
        next = id.saturating_add(1);
        match &e.geometry {
            Geometry::Curve(c) if c.dimension() == 2 => curves2.push(id),
            Geometry::Curve(_) => curves3.push(id),
            Geometry::Surface(_) => surfaces.push(id),
        }
        // A real is at most 24 bytes; typical ones about 18. An estimate: the string grows
        // if it is short.
        size = size
            .saturating_add(poles.saturating_mul(112))
            .saturating_add(reals.saturating_mul(24))
            .saturating_add(400);
    }
    f.b.reserve_many(next - first);
    let (set, rep_keyword) = geometric_set(&mut f.b, &curves3, &surfaces);
    let set: Vec<u64> = set.into_iter().collect();
    let header = finish(&mut f, options, rep_keyword, &set, &curves2);
    let scale = f.scale;
    let text = assemble(&mut f, &header, first, size, |out| {
        let mut id = first;
        for e in &document.entities {
            match &e.geometry {
                Geometry::Curve(c) => write_curve(out, &mut id, c, e, scale, options),
                Geometry::Surface(sf) => write_surface(out, &mut id, sf, e, scale, options),
            }?;
        }
        Ok(())
    })?;
    Ok((text, Vec::new()))
}

fn real_error(e: NonFiniteReal) -> Diagnostic {
    Diagnostic::error("step.write", e.to_string(), Location::default())
}

/// The file: the header records, the builder's instances before `first`, what `body`
/// writes (the ids from `first` the builder reserved), the builder's instances after.
fn assemble(
    f: &mut Frame,
    header: &[Record<'static>],
    first: u64,
    size: usize,
    body: impl FnOnce(&mut String) -> Result<(), NonFiniteReal>,
) -> Result<String, Diagnostic> {
    let instances = std::mem::take(&mut f.b).into_instances();
    let mut out = String::with_capacity(size);
    out.push_str("ISO-10303-21;\nHEADER;\n");
    for r in header {
        write_record(&mut out, r).map_err(real_error)?;
        out.push_str(";\n");
    }
    out.push_str("ENDSEC;\nDATA;\n");
    let split = instances.partition_point(|i| i.id < first);
    let (before, after) = instances.split_at(split);
    for inst in before {
        write_instance(&mut out, inst).map_err(real_error)?;
    }
    body(&mut out).map_err(real_error)?;
    for inst in after {
        write_instance(&mut out, inst).map_err(real_error)?;
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    Ok(out)
}

/// Whether a curve's ends coincide (the `closed_curve` flag).
fn curve_closed(c: &NurbsCurve) -> bool {
    let (d0, d1) = c.domain();
    distance(c.point_at_unchecked(d0), c.point_at_unchecked(d1))
        <= closure_tolerance(c.control_points())
}

/// Whether a surface's opposite boundaries coincide (`u_closed`, `v_closed`), sampled at
/// nine parameters along each boundary.
fn surface_closed(sf: &NurbsSurface) -> (bool, bool) {
    let tol = closure_tolerance(sf.control_points().as_slice());
    let ((u0, u1), (v0, v1)) = sf.domain();
    let mut gap_u: f64 = 0.0;
    let mut gap_v: f64 = 0.0;
    for k in 0..=8 {
        let t = f64::from(k) / 8.0;
        let v = v0 + (v1 - v0) * t;
        let u = u0 + (u1 - u0) * t;
        gap_u = gap_u.max(distance(
            sf.point_at_unchecked(u0, v),
            sf.point_at_unchecked(u1, v),
        ));
        gap_v = gap_v.max(distance(
            sf.point_at_unchecked(u, v0),
            sf.point_at_unchecked(u, v1),
        ));
    }
    (gap_u <= tol, gap_v <= tol)
}

/// The records of one curve: its poles (ids from `*id` on) and its B-spline (the next id),
/// written by the Part 21 record writers; `id` is left at the next free id.
fn write_curve(
    out: &mut String,
    id: &mut u64,
    c: &NurbsCurve,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result<(), NonFiniteReal> {
    // Stopped: skip (`exchange::write` discards the text).
    if options.cancel.is_set() {
        return Ok(());
    }
    let first = *id;
    for p in c.control_points() {
        write_point(out, *id, p, c.dimension(), scale)?;
        *id += 1;
    }
    let cid = *id;
    *id += 1;
    let knots = knot_spec(curve_subtype(c, options), || {
        let (values, mults) = crate::nurbs::knots::to_distinct(c.knots());
        (
            PerDirection::curve(counts(&mults)),
            PerDirection::curve(values),
            knot_form(c.degree(), c.knots()),
        )
    });
    let record = BSplineCurve {
        name: Some(StepString::from_text(e.meta.name.as_deref().unwrap_or(""))),
        degree: i64::try_from(c.degree()).unwrap_or(i64::MAX),
        control_points: (first..cid).collect(),
        curve_form: checked_form(e).unwrap_or("UNSPECIFIED"),
        closed_curve: curve_closed(c).into(),
        self_intersect: e.meta.self_intersect.unwrap_or(false).into(),
        knots,
        weights: c.weights().map(<[f64]>::to_vec),
        entity_type: Default::default(),
    };
    write_bspline_curve(out, cid, &record)
}

/// The records of one surface: its poles row by row, then its B-spline, as
/// [`write_curve`].
fn write_surface(
    out: &mut String,
    id: &mut u64,
    sf: &NurbsSurface,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result<(), NonFiniteReal> {
    // Stopped: skip (`exchange::write` discards the text).
    if options.cancel.is_set() {
        return Ok(());
    }
    let net = sf.control_points();
    let nu = net.nu();
    let mut rows = Vec::with_capacity(nu);
    for i in 0..nu {
        // Stopped in a large net: skip the rest (as above).
        if options.cancel.is_set() {
            return Ok(());
        }
        let row_first = *id;
        for p in net.row(i) {
            write_point(out, *id, p, sf.dimension(), scale)?;
            *id += 1;
        }
        rows.push((row_first..*id).collect());
    }
    let sid = *id;
    *id += 1;
    let knots = knot_spec(surface_subtype(sf, options), || {
        let (ku, mu) = crate::nurbs::knots::to_distinct(sf.knots_u());
        let (kv, mv) = crate::nurbs::knots::to_distinct(sf.knots_v());
        let fu = knot_form(sf.degree_u(), sf.knots_u());
        let fv = knot_form(sf.degree_v(), sf.knots_v());
        let spec = if fu == fv { fu } else { "UNSPECIFIED" };
        (
            PerDirection::surface(counts(&mu), counts(&mv)),
            PerDirection::surface(ku, kv),
            spec,
        )
    });
    let (closed_u, closed_v) = surface_closed(sf);
    let record = BSplineSurface {
        name: Some(StepString::from_text(e.meta.name.as_deref().unwrap_or(""))),
        u_degree: i64::try_from(sf.degree_u()).unwrap_or(i64::MAX),
        v_degree: i64::try_from(sf.degree_v()).unwrap_or(i64::MAX),
        control_points: rows,
        surface_form: checked_form(e).unwrap_or("UNSPECIFIED"),
        u_closed: closed_u.into(),
        v_closed: closed_v.into(),
        self_intersect: e.meta.self_intersect.unwrap_or(false).into(),
        knots,
        weights: sf
            .weights()
            .map(|w| (0..nu).map(|i| w.row(i).to_vec()).collect()),
        entity_type: Default::default(),
    };
    write_bspline_surface(out, sid, &record)
}

/// `#id = CARTESIAN_POINT('',(x,y[,z]));` with the first `dim` coordinates, scaled.
fn write_point(
    out: &mut String,
    id: u64,
    p: &crate::nurbs::Point3,
    dim: usize,
    scale: f64,
) -> Result<(), NonFiniteReal> {
    let scaled = [p[0] * scale, p[1] * scale, p[2] * scale];
    let point = CartesianPoint {
        name: Some(StepString::new("")),
        coordinates: Cow::Borrowed(scaled.get(..dim).unwrap_or(&scaled)),
    };
    write_cartesian_point(out, id, &point)
}

/// The implicit-knot subtype a curve is written as, if the options allow one and Open
/// CASCADE translates it.
fn curve_subtype(c: &NurbsCurve, options: &ExportOptions) -> Option<KnotForm> {
    let n = c.num_poles();
    if !options.use_implicit_knot_subtypes {
        return None;
    }
    implicit_subtype(c.degree(), n, c.knots())
        .filter(|&f| occt_translates(f, c.is_rational(), &[(c.degree(), n)]))
}

/// The implicit-knot subtype a surface is written as: the same one in both directions, if
/// the options allow one and Open CASCADE translates it.
fn surface_subtype(sf: &NurbsSurface, options: &ExportOptions) -> Option<KnotForm> {
    if !options.use_implicit_knot_subtypes {
        return None;
    }
    let (nu, nv) = (sf.control_points().nu(), sf.control_points().nv());
    let su = implicit_subtype(sf.degree_u(), nu, sf.knots_u());
    let sv = implicit_subtype(sf.degree_v(), nv, sf.knots_v());
    let dims = [(sf.degree_u(), nu), (sf.degree_v(), nv)];
    if su == sv {
        su.filter(|&f| occt_translates(f, sf.is_rational(), &dims))
    } else {
        None
    }
}

/// The knot attributes: the implicit subtype's, else the explicit lists `explicit` makes.
fn knot_spec(
    subtype: Option<KnotForm>,
    explicit: impl FnOnce() -> (PerDirection<i64>, PerDirection<f64>, &'static str),
) -> KnotSpec<'static> {
    match subtype {
        Some(KnotForm::Bezier) => KnotSpec::Bezier,
        Some(KnotForm::Uniform) => KnotSpec::Uniform,
        Some(KnotForm::QuasiUniform) => KnotSpec::QuasiUniform,
        None => {
            let (multiplicities, knots, knot_spec) = explicit();
            KnotSpec::Explicit {
                multiplicities,
                knots,
                knot_spec,
            }
        }
    }
}

/// Multiplicities as the INTEGERs of the record.
fn counts(mults: &[usize]) -> Vec<i64> {
    mults
        .iter()
        .map(|&m| i64::try_from(m).unwrap_or(i64::MAX))
        .collect()
}

/// The representation context with length, angle and solid-angle units and the length
/// uncertainty `uncertainty` (in the length unit; Open CASCADE writes 1e-7).
fn context(b: &mut Builder, unit: LengthUnit, dimension: i64, uncertainty: f64) -> u64 {
    let length = length_unit(b, unit);
    let angle = b.complex(vec![
        rec("NAMED_UNIT", vec![Parameter::Derived]),
        rec("PLANE_ANGLE_UNIT", vec![]),
        rec(
            "SI_UNIT",
            vec![Parameter::Null, Parameter::Enumeration("RADIAN")],
        ),
    ]);
    let solid = b.complex(vec![
        rec("NAMED_UNIT", vec![Parameter::Derived]),
        rec(
            "SI_UNIT",
            vec![Parameter::Null, Parameter::Enumeration("STERADIAN")],
        ),
        rec("SOLID_ANGLE_UNIT", vec![]),
    ]);
    let unc = b.simple(
        "UNCERTAINTY_MEASURE_WITH_UNIT",
        vec![
            Parameter::Typed("LENGTH_MEASURE", Box::new(Parameter::Real(uncertainty))),
            Parameter::Reference(length),
            s("distance_accuracy_value"),
            s("confusion accuracy"),
        ],
    );
    b.complex(vec![
        rec(
            "GEOMETRIC_REPRESENTATION_CONTEXT",
            vec![Parameter::Integer(dimension)],
        ),
        rec(
            "GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT",
            vec![Parameter::refs(&[unc])],
        ),
        rec(
            "GLOBAL_UNIT_ASSIGNED_CONTEXT",
            vec![Parameter::refs(&[length, angle, solid])],
        ),
        rec(
            "REPRESENTATION_CONTEXT",
            vec![
                s("Context #1"),
                s(if dimension == 2 {
                    "2D Context with UNIT and UNCERTAINTY"
                } else {
                    "3D Context with UNIT and UNCERTAINTY"
                }),
            ],
        ),
    ])
}

/// `( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(prefix,.METRE.) )`, or for inch-based units the
/// conversion-based form Open CASCADE writes (`CONVERSION_BASED_UNIT('INCH',#m)` with
/// `#m = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#mm)`).
fn length_unit(b: &mut Builder, unit: LengthUnit) -> u64 {
    let si = |b: &mut Builder, prefix: Option<&'static str>| {
        b.complex(vec![
            rec("LENGTH_UNIT", vec![]),
            rec("NAMED_UNIT", vec![Parameter::Derived]),
            rec(
                "SI_UNIT",
                vec![
                    prefix.map_or(Parameter::Null, Parameter::Enumeration),
                    Parameter::Enumeration("METRE"),
                ],
            ),
        ])
    };
    let conversion = |b: &mut Builder, name: &str, mm: f64| {
        let base = si(b, Some("MILLI"));
        let factor = b.simple(
            "LENGTH_MEASURE_WITH_UNIT",
            vec![
                Parameter::Typed("LENGTH_MEASURE", Box::new(Parameter::Real(mm))),
                Parameter::Reference(base),
            ],
        );
        let dims = b.simple(
            "DIMENSIONAL_EXPONENTS",
            vec![
                Parameter::Real(1.0),
                Parameter::Real(0.0),
                Parameter::Real(0.0),
                Parameter::Real(0.0),
                Parameter::Real(0.0),
                Parameter::Real(0.0),
                Parameter::Real(0.0),
            ],
        );
        b.complex(vec![
            rec(
                "CONVERSION_BASED_UNIT",
                vec![s(name), Parameter::Reference(factor)],
            ),
            rec("LENGTH_UNIT", vec![]),
            rec("NAMED_UNIT", vec![Parameter::Reference(dims)]),
        ])
    };
    match unit {
        LengthUnit::Mm => si(b, Some("MILLI")),
        LengthUnit::Cm => si(b, Some("CENTI")),
        LengthUnit::M => si(b, None),
        LengthUnit::Km => si(b, Some("KILO")),
        LengthUnit::Um => si(b, Some("MICRO")),
        LengthUnit::In => conversion(b, "INCH", 25.4),
        LengthUnit::Ft => conversion(b, "FOOT", 304.8),
        LengthUnit::Mi => conversion(b, "MILE", 1_609_344.0),
        LengthUnit::Mil => conversion(b, "MIL", 0.0254),
        LengthUnit::Uin => conversion(b, "MICROINCH", 0.0000254),
    }
}

fn axis_placement(b: &mut Builder) -> u64 {
    let origin = b.simple(
        "CARTESIAN_POINT",
        vec![s(""), Parameter::reals(&[0.0, 0.0, 0.0])],
    );
    let z = b.simple("DIRECTION", vec![s(""), Parameter::reals(&[0.0, 0.0, 1.0])]);
    let x = b.simple("DIRECTION", vec![s(""), Parameter::reals(&[1.0, 0.0, 0.0])]);
    b.simple(
        "AXIS2_PLACEMENT_3D",
        vec![
            s(""),
            Parameter::Reference(origin),
            Parameter::Reference(z),
            Parameter::Reference(x),
        ],
    )
}

/// The implicit-knot subtype whose knots are exactly `knots`, if any.
fn implicit_subtype(degree: usize, poles: usize, knots: &[f64]) -> Option<KnotForm> {
    [KnotForm::Bezier, KnotForm::QuasiUniform, KnotForm::Uniform]
        .into_iter()
        .find(|&f| implicit_knots(f, degree, poles).is_ok_and(|k| k == knots))
}

/// Whether Open CASCADE translates this implicit-knot subtype (spec.md c.4): it drops
/// rational Bezier entities and reads a Bezier as a single span, so those are written with
/// explicit knots instead (always exact; verified with FreeCAD 0.20.2 / OCCT 7.6).
fn occt_translates(form: KnotForm, rational: bool, dims: &[(usize, usize)]) -> bool {
    match form {
        KnotForm::Bezier => !rational && dims.iter().all(|&(d, n)| n == d + 1),
        KnotForm::Uniform | KnotForm::QuasiUniform => true,
    }
}

/// The kind an entity is labelled with: `meta.shape`, else the `curve_form`/`surface_form`
/// it was read with (`meta.form`).
fn declared_shape(e: &Entity) -> Option<Shape> {
    if e.meta.shape.is_some() {
        return e.meta.shape;
    }
    form_shape(e.meta.form.as_deref()?)
}

/// The kind a `b_spline_curve_form` / `b_spline_surface_form` value names (any case);
/// `.POLYLINE_FORM.` is a line, `None` for the values with no kind in nurbsx.
pub(super) fn form_shape(form: &str) -> Option<Shape> {
    FORMS
        .iter()
        .find(|(_, name)| name.eq_ignore_ascii_case(form))
        .map(|(shape, _)| *shape)
}

/// ISO 10303-42 `b_spline_curve_form` / `b_spline_surface_form` of each [`Shape`].
const FORMS: &[(Shape, &str)] = &[
    (Shape::Line, "POLYLINE_FORM"),
    (Shape::Polyline, "POLYLINE_FORM"),
    (Shape::CircularArc, "CIRCULAR_ARC"),
    (Shape::EllipticArc, "ELLIPTIC_ARC"),
    (Shape::ParabolicArc, "PARABOLIC_ARC"),
    (Shape::HyperbolicArc, "HYPERBOLIC_ARC"),
    (Shape::Plane, "PLANE_SURF"),
    (Shape::Cylinder, "CYLINDRICAL_SURF"),
    (Shape::Cone, "CONICAL_SURF"),
    (Shape::Sphere, "SPHERICAL_SURF"),
    (Shape::Torus, "TOROIDAL_SURF"),
    (Shape::Revolution, "SURF_OF_REVOLUTION"),
    (Shape::Extrusion, "SURF_OF_LINEAR_EXTRUSION"),
    (Shape::Ruled, "RULED_SURF"),
];

/// The form to write: the declared kind's form when the geometry check
/// (`exchange::iges::form`) agrees; `Err` with the reason when a kind is declared and the
/// geometry disagrees; `Ok("UNSPECIFIED")` when nothing is declared. An IGES form number
/// (`meta.form` of a 126/128) is not a STEP form: the IGES reader turned the ones with a
/// kind into `meta.shape` and reported the others.
fn form_of(e: &Entity) -> Result<&'static str, String> {
    let declared = match declared_shape(e) {
        Some(s) => s,
        None => {
            return match e.meta.form.as_deref() {
                Some(f) if !f.eq_ignore_ascii_case("unspecified") && f.parse::<i64>().is_err() => {
                    Err(format!(
                        "form .{}. has no check in nurbsx",
                        f.to_ascii_uppercase()
                    ))
                }
                _ => Ok("UNSPECIFIED"),
            };
        }
    };
    // The kind's check is the one the IGES writer uses for its form numbers (one check per
    // kind, `exchange::iges::form`); a polyline label also needs degree 1.
    crate::exchange::iges::form(
        &e.geometry,
        Some(declared),
        e.meta.shape_tolerance.unwrap_or(0.0),
    )?;
    if let (Shape::Polyline, Geometry::Curve(c)) = (declared, &e.geometry) {
        if c.degree() != 1 {
            return Err("a polyline is degree 1".to_owned());
        }
    }
    FORMS
        .iter()
        .find(|(s, _)| *s == declared)
        .map(|(_, f)| *f)
        .ok_or_else(|| format!("{declared:?} has no STEP form"))
}

fn checked_form(e: &Entity) -> Option<&'static str> {
    form_of(e).ok()
}

/// One warning per entity whose declared kind (`meta.shape`, or the form it was read with)
/// the geometry does not agree with: the STEP writer writes `.UNSPECIFIED.` for it.
pub fn form_warnings(document: &Document) -> Vec<Diagnostic> {
    document
        .entities
        .iter()
        .filter_map(|e| {
            form_of(e).err().map(|why| {
                Diagnostic::warning(
                    "step.form_unspecified",
                    format!("curve_form/surface_form written as .UNSPECIFIED.: {why}"),
                    Location::at_entity(e.id.clone()),
                )
            })
        })
        .collect()
}

/// One warning per free curve or surface (one no face, edge or composite uses) whose
/// declared parameter range ([`crate::exchange::Meta::parameter_range`], an IGES
/// `V(0), V(1)` or `U(0)..V(1)`) is not its whole knot domain: a STEP B-spline has no such
/// range, so the writer writes the whole domain, a longer curve or larger surface than the
/// source meant. Reading with `trim_to_parameter_range` (`--trim-to-range`) cuts it to the
/// range exactly (NURBS Book A5.1) and there is nothing to report.
pub fn range_warnings(document: &Document) -> Vec<Diagnostic> {
    let named = document.topology.origins.entity_ids();
    document
        .entities
        .iter()
        .filter(|e| e.meta.used_by.is_empty() && !named.contains(e.id.as_str()))
        .filter_map(|e| {
            let declared = *e.meta.parameter_range.as_deref()?;
            let (u, v) = match &e.geometry {
                Geometry::Curve(c) => (c.domain(), None),
                Geometry::Surface(s) => {
                    let (u, v) = s.domain();
                    (u, Some(v))
                }
            };
            let same = ParameterRange::same_within_rounding(declared.u, u, u)
                && match (declared.v, v) {
                    (Some(r), Some(d)) => ParameterRange::same_within_rounding(r, d, d),
                    _ => true,
                };
            if same {
                return None;
            }
            let show = |r: (f64, f64)| format!("[{}, {}]", r.0, r.1);
            let (declared_text, domain_text) = match (declared.v, v) {
                (Some(r), Some(d)) => (
                    format!("{} x {}", show(declared.u), show(r)),
                    format!("{} x {}", show(u), show(d)),
                ),
                _ => (show(declared.u), show(u)),
            };
            Some(Diagnostic::warning(
                "range_not_written",
                format!(
                    "declared parameter range {declared_text} is not written: a STEP B-spline has none, so the whole knot domain {domain_text} is (read with --trim-to-range to convert the declared range exactly)"
                ),
                Location::at_entity(e.id.clone()),
            ))
        })
        .collect()
}

/// The current UTC time as `YYYY-MM-DDTHH:MM:SS` (civil-from-days, H. Hinnant's algorithm).
fn now_iso8601() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let days = i64::try_from(secs / 86_400).unwrap_or(0);
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}",
        rem / 3600,
        (rem % 3600) / 60,
        rem % 60
    )
}

/// The fast writer against the straightforward one: byte-identical text for every sample
/// file and for random documents (rational and polynomial curves and surfaces, 2-D curves,
/// implicit-knot subtypes, names needing escapes, and odd values: -0.0, 1e-300, 1e300,
/// subnormals, integers, short binary fractions).
#[cfg(test)]
mod equivalence_tests;
