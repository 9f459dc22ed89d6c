//! STEP file -> [`Document`]: every B-spline curve and surface, the other ISO 10303-42
//! geometry through `geometry.rs`, the length and plane-angle units, and located
//! diagnostics (module table in [`super`]).

use nurbsx_parsers::step::schema::{
    Attributes, BSpline, BSplineCurve, BSplineSurface, DecodeError, KnotSpec, Logical,
    SUPERTYPE_CHAINS, canonical_name,
};
use nurbsx_parsers::step::{
    ParseError, ParseErrorKind, RawInstance, Scanned, SchemaError, scan_parallel, schema_names,
};

use rayon::prelude::*;
use std::borrow::Cow;

use nurbsx_parsers::step::geometry::{is_geometry_entity, maybe_complex_geometry};
use nurbsx_parsers::step::product::{is_product_entity, maybe_complex_product};

use super::closure_tolerance;
use super::geometry::{ByInstance, Converter, Items, Kept, Units};
use super::implicit::{KnotForm, implicit_knots};
use super::units::{FileUnit, context_plane_angle, context_units, unit_contexts};
use crate::exchange::{
    Diagnostic, Document, Entity, Format, ImportOptions, LengthUnit, Location, Meta, Source,
};
use crate::nurbs::{Geometry, Grid, NurbsCurve, NurbsSurface, Point3, distance};

/// Reads every B-spline curve and surface of a STEP file (ISO 10303-21 + ISO 10303-42) and
/// its analytic, trimmed, composite and swept geometry.
///
/// Per-entity problems give an error diagnostic and the entity is skipped; the boundary
/// representation (faces, loops, edges, vertices, shells, solids) goes into
/// [`Document::topology`] unless [`ImportOptions::geometry_only`], with the placements
/// of the product structure applied (`assembly.rs`); the rest of the file (presentation)
/// is ignored without comment. `Err` only when the file structure is broken (no
/// `ISO-10303-21;`/`HEADER;`, or an input limit). Only instances that may be B-splines (and
/// the points, units and contexts they need) are decoded, so syntax errors in other
/// instances are not reported.
///
/// A file with lower-case keywords (not conforming, ISO 10303-21 clause 6.4) is read again
/// with its keywords upper-cased, each reported as a non-conforming finding at its line,
/// column and `#id` (the first read, where none was met, is the only one otherwise; where
/// the scan meets one, as in a file written all in lower case, the first read stops after
/// the scan).
pub fn read(text: &str, options: &ImportOptions) -> Result<Document, Diagnostic> {
    // The read runs on a thread of the pool its parallel parts use, not on the caller's:
    // glibc gives each thread its own heap (arena), and memory one frees is taken again
    // only by allocations of the same thread. On the caller's thread, the topology could
    // not reuse what the B-spline pass had freed on the pool's, and a one-thread read of a
    // 100 MB B-rep peaked 0.12x of the file higher.
    let first = rayon::scope(|_| read_text(text, options));
    let lower_case = |d: &Diagnostic| d.code == LOWER_CASE_KEYWORD;
    match &first {
        Ok(doc) if !doc.diagnostics.iter().any(lower_case) => return first,
        Err(d) if !lower_case(d) => return first,
        _ => {}
    }
    // The first reading is discarded before the copy is made and read.
    drop(first);
    options.cancel.stop_read()?;
    let mut upper = text.to_owned();
    let (count, listed) = nurbsx_parsers::step::upper_case_keywords(
        &mut upper,
        MAX_LOWER_CASE_LISTED,
        options.cancel.scan_stop(),
    )
    .map_err(|e| {
        options
            .cancel
            .stop_read()
            .err()
            .unwrap_or_else(|| parse_diagnostic(&e))
    })?;
    let mut doc = read_text(&upper, options)?;
    let mut found: Vec<Diagnostic> = listed
        .iter()
        .map(|e| {
            let d = parse_diagnostic(e);
            Diagnostic::nonconforming(
                d.code,
                format!(
                    "{}; read as upper case (ISO 10303-21 clause 6.4: keywords are upper case)",
                    d.message
                ),
                d.location,
            )
        })
        .collect();
    if count > listed.len() {
        found.push(Diagnostic::nonconforming(
            LOWER_CASE_KEYWORD,
            format!(
                "{count} keywords in all are not upper case; only the first {} are listed",
                listed.len()
            ),
            Location::default(),
        ));
    }
    found.append(&mut doc.diagnostics);
    doc.diagnostics = found;
    Ok(doc)
}

/// The code of a keyword with lower-case letters (ISO 10303-21 clause 6.4).
const LOWER_CASE_KEYWORD: &str = "step.syntax.lowercase_keyword";
/// How many lower-case keywords are listed one by one (a file written all in lower case has
/// one per instance); the rest are counted.
const MAX_LOWER_CASE_LISTED: usize = 100;

/// A geometry candidate decoded: the item as kept, none (not a geometry instance after
/// all), or why not.
type Decoded<'a> = Result<Option<Kept<'a>>, Box<DecodeError>>;

/// [`read`] of a text read as written.
fn read_text(text: &str, options: &ImportOptions) -> Result<Document, Diagnostic> {
    // The scan splits large DATA sections over the same threads that decode the B-splines
    // below (identical result to a one-thread scan; see `scan_parallel`).
    let cancel = &options.cancel;
    let scanned = scan_parallel(
        text,
        &options.limits,
        rayon::current_num_threads(),
        cancel.scan_stop(),
    )
    .map_err(|e| match e.kind {
        ParseErrorKind::Stopped => cancel
            .stop_read()
            .err()
            .unwrap_or_else(|| parse_diagnostic(&e)),
        _ => parse_diagnostic(&e),
    })?;
    cancel.stop_read()?;
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    let schemas: Vec<String> = schema_names(&scanned.header)
        .iter()
        .map(|s| s.decode_lossy().into_owned())
        .collect();
    doc.schema = (!schemas.is_empty()).then(|| schemas.join(", "));
    for e in &scanned.errors {
        doc.diagnostics.push(parse_diagnostic(e));
    }
    // One pass over the instances (a large file has millions, and each pass over them is a
    // pass over memory) finds both the B-spline candidates and the complex instances, where
    // the unit context is.
    let mut candidates: Vec<&RawInstance<'_>> = Vec::new();
    let mut complex: Vec<&RawInstance<'_>> = Vec::new();
    let mut geometry_candidates: Vec<&RawInstance<'_>> = Vec::new();
    // The product structure (assembly.rs).
    let mut product_candidates: Vec<&RawInstance<'_>> = Vec::new();
    let mut presentation = Presentation::default();
    let mut classes = Classes::default();
    for (k, raw) in scanned.instances.iter().enumerate() {
        if k % crate::exchange::READ_POLL == 0 {
            cancel.stop_read()?;
        }
        // Most instances of a file are CARTESIAN_POINTs, which none of the lists below
        // takes (the entities using them read them): one comparison turns them away.
        if raw.keyword_initial() == Some(b'C') && raw.keyword(text) == Some("CARTESIAN_POINT") {
            continue;
        }
        if raw.keyword_initial().is_none() {
            // A simple instance whose keyword has lower-case letters (the scanner keeps
            // upper-case keywords only): [`read`] reads the file again upper-cased and keeps
            // nothing else of this reading, so nothing is decoded here.
            if raw.body(text).starts_with(|c: char| c.is_ascii_lowercase()) {
                if let Err(e) = scanned.decode(raw) {
                    if matches!(e.kind, ParseErrorKind::LowercaseKeyword(_)) {
                        doc.diagnostics = vec![parse_diagnostic(&e)];
                        return Ok(doc);
                    }
                }
            }
            complex.push(raw);
        }
        presentation.count(text, raw);
        // A duplicated id was reported by the scanner; only the indexed (first) one is read.
        let indexed = || scanned.get(raw.id).map(|r| r.offset()) == Some(raw.offset());
        let class = classes.of(text, raw);
        if class.bspline {
            // No B-spline keyword is a product-structure one; a complex B-spline candidate
            // (a rational B-spline's long body) is searched for product partials only if
            // it does not decode as a B-spline (below).
            if indexed() {
                candidates.push(raw);
            }
            continue;
        }
        if class.product && indexed() {
            product_candidates.push(raw);
        }
        if class.geometry && indexed() {
            geometry_candidates.push(raw);
        }
    }
    let contexts = unit_contexts(&scanned, complex);
    let (scale, uncertainty) = file_units(&scanned, &contexts, options, &mut doc);

    // The other ISO 10303-42 geometry and the topology bounding it: decoded in parallel,
    // then converted (geometry.rs), which also says which B-splines it built into other
    // entities (trimmed, composite, swept): those are not converted again below.
    let stopped = std::sync::atomic::AtomicBool::new(false);
    // Kept as the reader keeps them (`Kept`: no name or type text), with the rare errors
    // boxed, so that this vector, the largest of the read while it lives, is no larger
    // than the items it becomes.
    // The decoders look up the lines of the items (`Kept::new`): the line table is built
    // here, before them, not by the first of them while the others wait.
    let _ = scanned.line(0);
    let decoded: Vec<(u64, Decoded<'_>)> = geometry_candidates
        .par_iter()
        .enumerate()
        .map(|(k, raw)| {
            if cancel.skip(k, &stopped) {
                return (raw.id, Ok(None));
            }
            let item = scanned.geometry_item(raw);
            let kept = |i| Kept::new(i, &scanned, raw.offset());
            (raw.id, item.map(|i| i.map(kept)).map_err(Box::new))
        })
        .collect();
    // Every instance index no longer needed is freed before the read's peak (the topology,
    // below).
    drop(geometry_candidates);
    cancel.stop_read()?;
    // Gathered in place (the standard library reuses `decoded`'s buffer, then fits it): a
    // second vector of every item beside it was the read's peak of memory.
    let mut items = Items::gather(decoded, |r| match r {
        Ok(item) => item,
        Err(e) => {
            doc.diagnostics.push(match *e {
                DecodeError::Syntax(e) => parse_diagnostic(&e),
                DecodeError::Schema(e) => schema_diagnostic(&e),
            });
            None
        }
    });
    let radians = if items.is_empty() {
        1.0
    } else {
        plane_angle(&scanned, &contexts, &mut doc)
    };
    // The candidate lists are freed once used (each is a pointer per instance of its kind).
    drop(contexts);
    let decode = |raw: &RawInstance<'_>| decode_bspline(&scanned, raw, options, scale);
    // The B-splines the geometry below builds into edges, trims and sweeps, converted once:
    // the B-spline pass after it takes them from here (an edge's curve and its entity share
    // their poles) instead of decoding them again. What was noticed on the way is kept with
    // them; for the B-splines consumed by other entities (not converted again below) it is
    // reported from `bspline_notes`. `None` once moved into the entities; the first
    // converted stays (two threads may convert one B-spline at once, equally).
    let converted_bsplines: std::sync::Mutex<ByInstance<Option<Noted>>> = Default::default();
    let bspline_notes: std::sync::Mutex<Vec<(u64, Vec<Diagnostic>)>> = Default::default();
    let bspline = |raw: &RawInstance<'_>| -> Result<Option<Entity>, Diagnostic> {
        if let Some(e) = converted_bsplines.lock().ok().and_then(|c| {
            c.get(raw.id)
                .and_then(Option::as_ref)
                .map(|(e, _)| e.clone())
        }) {
            return Ok(Some(e));
        }
        let (r, diags) = decode(raw);
        if let Ok(Some(e)) = &r {
            if let Ok(mut c) = converted_bsplines.lock() {
                c.push(raw.id, Some((e.clone(), diags.clone())));
            }
        }
        if !diags.is_empty() {
            if let Ok(mut all) = bspline_notes.lock() {
                all.push((raw.id, diags));
            }
        }
        r
    };
    let units = Units {
        scale,
        radians,
        uncertainty,
    };
    let converter = Converter::new(&scanned, &items, units, &bspline);
    let mut converted = converter.run(candidates.len());
    // Read once by the conversion, for the topology's vertices.
    let points = converter.into_points();
    cancel.stop_read()?;
    let edges = std::mem::take(&mut converted.edges);
    let quadric_maps = std::mem::take(&mut converted.quadric_maps);
    doc.diagnostics.extend(converted.diagnostics);
    let consumed = converted.consumed_bsplines;
    if let Ok(mut notes) = bspline_notes.lock() {
        notes.sort_by_key(|(id, _)| *id);
        notes.dedup_by_key(|(id, _)| *id);
        for (id, d) in notes.drain(..) {
            if consumed.contains(&id) {
                doc.diagnostics.extend(d);
            }
        }
    }
    candidates.retain(|raw| !consumed.contains(&raw.id));
    // The 2-D curves of the edges' PCURVEs, read before the items they come from are freed.
    let edge_pcurves = if options.geometry_only {
        Vec::new()
    } else {
        super::topology::edge_pcurve_curves(&items, &std::mem::take(&mut converted.edge_items))
    };
    // The curves and surfaces are converted: what the topology and the product structure
    // read is kept, the rest of the decoded items freed before the read's peak of memory
    // (the B-spline entities below, then the topology). The product structure is decoded
    // first for the placements it reads as frames. A complex B-spline candidate may turn
    // out to be a product item (below, when it is no B-spline), naming more: then both wait
    // for the B-spline pass.
    let mut product_diagnostics = Vec::new();
    let mut products = None;
    if !options.geometry_only
        && !candidates
            .iter()
            .any(|raw| raw.keyword_initial().is_none() && maybe_product(text, raw))
    {
        let early = decode_products(&scanned, &product_candidates, &mut product_diagnostics);
        keep_for_topology(&mut items, &early);
        products = Some(early);
    }

    // Each B-spline is independent once the file is scanned: decoded in parallel (rayon
    // keeps the file order in `collect`), a chunk at a time, each chunk's results appended
    // in order. `placed` has room for one entity per candidate (each gives at most one), so
    // the entities are never held twice: a vector of every result beside `placed` was the
    // read's peak of memory.
    let mut placed: Vec<(usize, Entity)> = converted.entities;
    placed.reserve_exact(candidates.len());
    // The B-splines converted above for the edges and sweeps that use them (and not
    // consumed by them) are entities of their own: moved into `placed` now, in file order,
    // and left out of the pass. Their table is freed before the pass fills `placed`: held
    // through it (a few hundred bytes an entry), it was a sixth of the file at the read's
    // peak. What was noticed on the way is reported where the pass would have reported it.
    let mut converted_notes: std::collections::VecDeque<(usize, Vec<Diagnostic>)> =
        Default::default();
    if let Ok(mut map) = converted_bsplines.lock() {
        if !map.is_empty() {
            candidates.retain(|raw| match map.get_mut(raw.id).and_then(Option::take) {
                Some((e, diags)) => {
                    placed.push((raw.offset(), e));
                    if !diags.is_empty() {
                        converted_notes.push_back((raw.offset(), diags));
                    }
                    false
                }
                None => true,
            });
        }
        // Only the consumed B-splines are left: their entities are the edges' and sweeps'
        // own.
        *map = Default::default();
    }
    // The B-spline 2-D curves of the edges' PCURVEs wait for the topology, which computes
    // its own pcurves: converted after it only where it did not (`defer_pcurve_curves`).
    // The conformance checks read every instance as it is.
    let deferred = if options.conformance {
        Vec::new()
    } else {
        defer_pcurve_curves(&mut candidates, &edge_pcurves, text)
    };
    let mut late_products = false;
    for (c, chunk) in candidates.chunks(BSPLINE_CHUNK).enumerate() {
        let results: Vec<(Option<Entity>, Vec<Diagnostic>)> = chunk
            .par_iter()
            .enumerate()
            .map(|(i, raw)| {
                if cancel.skip(c * BSPLINE_CHUNK + i, &stopped) {
                    return (None, Vec::new());
                }
                let (result, mut diags) = decode(raw);
                match result {
                    Ok(e) => (e, diags),
                    Err(d) => {
                        diags.push(d);
                        (None, diags)
                    }
                }
            })
            .collect();
        cancel.stop_read()?;
        for ((entity, diags), raw) in results.into_iter().zip(chunk) {
            while converted_notes
                .front()
                .is_some_and(|(at, _)| *at < raw.offset())
            {
                doc.diagnostics
                    .extend(converted_notes.pop_front().into_iter().flat_map(|(_, d)| d));
            }
            doc.diagnostics.extend(diags);
            if entity.is_none() && raw.keyword_initial().is_none() && maybe_product(text, raw) {
                product_candidates.push(raw);
                late_products = true;
            }
            placed.extend(entity.map(|e| (raw.offset(), e)));
        }
    }
    doc.diagnostics
        .extend(converted_notes.into_iter().flat_map(|(_, d)| d));
    placed.shrink_to_fit();
    drop(candidates);
    if late_products {
        product_candidates.sort_by_key(|raw| raw.offset());
    }
    // File order (a stable sort: entities of one instance keep their order).
    placed.sort_by_key(|(offset, _)| *offset);
    if doc.entities.is_empty() {
        // Collected in place (the standard library reuses `placed`'s buffer).
        doc.entities = placed.into_iter().map(|(_, e)| e).collect();
    } else {
        doc.entities.extend(placed.into_iter().map(|(_, e)| e));
    }

    // The boundary representation over the converted geometry (topology.rs).
    let mut pcurve_users = Vec::new();
    if options.geometry_only {
        doc.diagnostics.extend(converted.analytic_pcurves.take());
        let c = super::topology::count(&Converter::new(&scanned, &items, units, &bspline));
        if c != super::topology::Counts::default() {
            doc.diagnostics.push(Diagnostic::warning(
                "topology.not_read",
                format!(
                    "read geometry only: {} face(s), {} edge(s), {} shell(s) and {} solid(s) of the file are not represented (their surfaces and curves are)",
                    c.faces, c.edges, c.shells, c.solids
                ),
                Location::default(),
            )
            .not_carried());
        }
    } else {
        // The product structure and the items kept for it, unless done above.
        let products = match products {
            Some(p) => p,
            None => {
                let p = decode_products(&scanned, &product_candidates, &mut product_diagnostics);
                keep_for_topology(&mut items, &p);
                p
            }
        };
        drop(product_candidates);
        // Every B-spline is converted by now, and the topology and the product structure
        // read none (a face's surface and an edge's curve are entities by now): one asked
        // for here would be a reader error, and is reported as one.
        let no_bspline = |raw: &RawInstance<'_>| -> Result<Option<Entity>, Diagnostic> {
            Err(Diagnostic::error(
                "internal",
                format!("B-spline #{} asked for after the B-spline pass", raw.id),
                Location::default(),
            ))
        };
        let converter = Converter::new(&scanned, &items, units, &no_bspline).with_points(points);
        let built = super::topology::build(
            &converter,
            edges,
            &quadric_maps,
            &doc.entities,
            uncertainty,
            &edge_pcurves,
        );
        cancel.stop_read()?;
        // The file's 2-D curves of the edges whose coedges did not all get a pcurve.
        let needed = pcurve_curves_needed(deferred, &edge_pcurves, &built.edges_with_pcurves);
        drop(edge_pcurves);
        let late: Vec<BSplineRead> = needed
            .par_iter()
            .filter_map(|&id| scanned.get(id))
            .map(|raw| decode_bspline(&scanned, raw, options, scale))
            .collect();
        for (r, diags) in late {
            doc.diagnostics.extend(diags);
            match r {
                Ok(e) => doc.entities.extend(e),
                Err(d) => doc.diagnostics.push(d),
            }
        }
        doc.topology = built.topology;
        doc.adopt_moved_surfaces(&built.moved_faces);
        doc.diagnostics.extend(built.diagnostics);
        doc.diagnostics.extend(product_diagnostics);
        doc.diagnostics.extend(super::assembly::apply(
            &converter,
            &products,
            &doc.entities,
            &mut doc.topology,
            options.limits.max_entities,
        ));
        pcurve_users = built.pcurve_entities;
    }
    doc.diagnostics.extend(presentation.diagnostic(&scanned));
    if options.conformance {
        cancel.stop_read()?;
        header_conformance(text, &scanned, &mut doc.diagnostics);
        conformance(&scanned, &mut doc.diagnostics, cancel)?;
    }
    // The instance index and the decoded items are freed before the labels below are made
    // (the read's peak of memory was there, with both alive).
    drop(items);
    drop(scanned);
    label_pcurve_users(&mut doc.entities, pcurve_users);
    // The same finding reached by two paths (a syntax error in a B-spline instance is met by
    // the scan and by the decoder) is reported once.
    let mut seen = std::collections::HashSet::new();
    doc.diagnostics
        .retain(|d| seen.insert((d.code.clone(), d.message.clone(), d.location.to_string())));
    Ok(doc)
}

/// How many B-spline candidates are decoded (in parallel) before their entities are moved
/// into the document's list: enough to keep the threads busy, few enough that the chunk's
/// results are a small part of the read's memory.
const BSPLINE_CHUNK: usize = 4096;

/// An entity with what was noticed while converting it.
type Noted = (Entity, Vec<Diagnostic>);

/// A B-spline instance read ([`decode_bspline`]): the entity (or why not) and what was
/// noticed on the way.
type BSplineRead = (Result<Option<Entity>, Diagnostic>, Vec<Diagnostic>);

/// One B-spline instance, decoded and converted.
fn decode_bspline(
    s: &Scanned<'_>,
    raw: &RawInstance<'_>,
    options: &ImportOptions,
    scale: f64,
) -> BSplineRead {
    let ctx = Ctx {
        s,
        raw,
        options,
        scale,
    };
    let mut diags = Vec::new();
    let r = match s.bspline(raw) {
        Ok(Some(BSpline::Curve(r))) => ctx.curve_record(r, &mut diags).map(Some),
        Ok(Some(BSpline::Surface(r))) => ctx.surface_record(r, &mut diags).map(Some),
        Ok(None) => Ok(None),
        Err(DecodeError::Syntax(e)) => Err(parse_diagnostic(&e)),
        Err(DecodeError::Schema(e)) => Err(ctx.error("step.schema", e.detail())),
    };
    (r, diags)
}

/// Takes the B-spline candidates that are 2-D curves of the edges' PCURVEs (`edge_pcurves`,
/// `(edge, curve)` pairs) out of `candidates`, and returns their ids in file order. The
/// topology computes every coedge's pcurve on its face's NURBS surface (the file's are in
/// the parameters of the file's surfaces, which for an analytic surface are not the NURBS
/// ones); the file's own curve is converted after it only for an edge whose coedges did not
/// all get one ([`pcurve_curves_needed`]). On a B-spline B-rep these are most of the
/// B-spline instances. A complex instance that may be a product item stays a candidate (it
/// is looked at as one if it is no B-spline).
fn defer_pcurve_curves(
    candidates: &mut Vec<&RawInstance<'_>>,
    edge_pcurves: &[(u64, u64)],
    text: &str,
) -> Vec<u64> {
    if edge_pcurves.is_empty() {
        return Vec::new();
    }
    let mut curves: Vec<u64> = edge_pcurves.iter().map(|&(_, c)| c).collect();
    curves.sort_unstable();
    curves.dedup();
    let mut deferred = Vec::new();
    candidates.retain(|raw| {
        let pcurve = curves.binary_search(&raw.id).is_ok()
            && !(raw.keyword_initial().is_none() && maybe_product(text, raw));
        if pcurve {
            deferred.push(raw.id);
        }
        !pcurve
    });
    deferred
}

/// The deferred 2-D curves ([`defer_pcurve_curves`]) that some edge listing them needs
/// converted: an edge not in the topology, or one with a coedge left without a pcurve
/// (`carried`: the edges whose every coedge has one, ascending; `edge_pcurves` as there).
/// In `deferred`'s order.
fn pcurve_curves_needed(
    mut deferred: Vec<u64>,
    edge_pcurves: &[(u64, u64)],
    carried: &[u64],
) -> Vec<u64> {
    if deferred.is_empty() {
        return deferred;
    }
    let mut needed: Vec<u64> = edge_pcurves
        .iter()
        .filter(|(edge, _)| carried.binary_search(edge).is_err())
        .map(|&(_, curve)| curve)
        .collect();
    needed.sort_unstable();
    needed.dedup();
    deferred.retain(|id| needed.binary_search(id).is_ok());
    deferred
}

/// Frees the decoded items the topology and the product structure do not read (the
/// curves and surfaces are converted by now), keeping the placements `products` reads as
/// frames.
fn keep_for_topology(items: &mut Items<'_>, products: &super::assembly::Products<'_>) {
    let frames = super::assembly::frame_items(products, items);
    items.retain(|id, record| super::topology::reads(record) || frames.contains(&id));
}

/// The product-structure candidates decoded (assembly.rs); errors are diagnostics.
fn decode_products<'a>(
    s: &Scanned<'a>,
    candidates: &[&RawInstance<'a>],
    diagnostics: &mut Vec<Diagnostic>,
) -> super::assembly::Products<'a> {
    super::assembly::decode(s, candidates, diagnostics, |e| match e {
        DecodeError::Syntax(e) => parse_diagnostic(&e),
        DecodeError::Schema(e) => schema_diagnostic(&e),
    })
}

/// Adds to each 2-D curve entity the edges whose pcurve it is (`Meta::used_by`), from the
/// `(curve, edge)` instance pairs the topology found, in their order. The entity of
/// instance #n is labelled `#n` (`instance_label`); of several entities with one label the
/// first takes the list.
fn label_pcurve_users(entities: &mut [Entity], mut pairs: Vec<(u64, u64)>) {
    if pairs.is_empty() {
        return;
    }
    // A stable sort: each curve's edges stay in the order found.
    pairs.sort_by_key(|&(curve, _)| curve);
    let mut taken = vec![false; pairs.len()];
    let mut cursor = 0;
    for e in entities {
        let Some(id) = super::instance_of(&e.id) else {
            continue;
        };
        // Entities come in file order, ids ascending in most files: the search gallops on
        // from where the previous one ended (neighbouring memory), and searches the whole
        // list only for an id out of order.
        let start = if cursor > 0 && pairs[cursor - 1].0 >= id {
            pairs.partition_point(|&(curve, _)| curve < id)
        } else {
            cursor + first_not_below(&pairs[cursor..], id, |&(curve, _)| curve)
        };
        let end = start
            + pairs[start..]
                .iter()
                .take_while(|&&(curve, _)| curve == id)
                .count();
        cursor = end;
        if start == end || taken[start] {
            continue;
        }
        taken[start] = true;
        e.meta.used_by.extend(
            pairs[start..end]
                .iter()
                .map(|&(_, edge)| super::instance_label(edge)),
        );
    }
}

/// The first index of `pairs` (sorted by their first element) whose first element is not
/// below `id`, found by galloping from the start: a few steps when it is near.
fn first_not_below<T>(sorted: &[T], id: u64, key: impl Fn(&T) -> u64) -> usize {
    // sorted[..lo] are all below `id`; the probe at lo + step - 1 either is too, or ends
    // the gallop.
    let (mut lo, mut step) = (0, 1);
    while let Some(x) = sorted.get(lo + step - 1) {
        if key(x) >= id {
            break;
        }
        lo += step;
        step *= 2;
    }
    let hi = (lo + step).min(sorted.len());
    lo + sorted[lo..hi].partition_point(|x| key(x) < id)
}

/// The presentation and property data of a file, which nurbsx does not carry into its
/// model or output (ISO 10303-46 styled_item and presentation_layer_assignment, ISO 10303-41
/// property_definition: colours, layers, materials, validation properties): counted in the
/// one pass over the instances, reported once as a warning so that no colour is lost in
/// silence.
#[derive(Default)]
struct Presentation {
    /// STYLED_ITEM and OVER_RIDING_STYLED_ITEM instances (colours and styles).
    styled: usize,
    /// PRESENTATION_LAYER_ASSIGNMENT instances.
    layers: usize,
    /// PROPERTY_DEFINITION instances.
    properties: usize,
    /// The first of them, for the location.
    first: Option<u64>,
}

impl Presentation {
    /// Counts `raw` when it is one of the kinds above (one byte compared for most instances).
    fn count(&mut self, text: &str, raw: &RawInstance<'_>) {
        let slot = match raw.keyword_initial() {
            Some(b'S' | b'O' | b'P') => match raw.keyword(text) {
                Some("STYLED_ITEM" | "OVER_RIDING_STYLED_ITEM") => &mut self.styled,
                Some("PRESENTATION_LAYER_ASSIGNMENT") => &mut self.layers,
                Some("PROPERTY_DEFINITION") => &mut self.properties,
                _ => return,
            },
            _ => return,
        };
        *slot += 1;
        self.first = Some(self.first.map_or(raw.id, |f| f.min(raw.id)));
    }

    /// The warning that names what is not carried, if anything.
    fn diagnostic(&self, s: &Scanned<'_>) -> Option<Diagnostic> {
        let first = self.first?;
        let parts: Vec<String> = [
            (self.styled, "STYLED_ITEM (colours and styles)"),
            (self.layers, "PRESENTATION_LAYER_ASSIGNMENT (layers)"),
            (self.properties, "PROPERTY_DEFINITION (properties)"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} x {what}"))
        .collect();
        let (line, column) = s
            .get(first)
            .map(|r| s.locate(r.offset()))
            .map_or((None, None), |(l, c)| (Some(l), Some(c)));
        Some(
            Diagnostic::warning(
                "presentation.not_carried",
                format!(
                    "presentation and property data are not carried into the model or its output: {}",
                    parts.join(", ")
                ),
                Location {
                    line,
                    column,
                    entity: Some(super::instance_label(first).into()),
                    ..Location::default()
                },
            )
            .not_carried(),
        )
    }
}

/// The HEADER section holds FILE_DESCRIPTION (2 attributes), FILE_NAME (7) and FILE_SCHEMA
/// (1), in this order, before any other header entity (ISO 10303-21 clause 8.2).
fn header_conformance(text: &str, s: &Scanned<'_>, diags: &mut Vec<Diagnostic>) {
    const REQUIRED: [(&str, usize); 3] = [
        ("FILE_DESCRIPTION", 2),
        ("FILE_NAME", 7),
        ("FILE_SCHEMA", 1),
    ];
    let (line, column) = s.locate(text.find("HEADER").unwrap_or(0));
    let location = Location {
        line: Some(line),
        column: Some(column),
        ..Location::default()
    };
    for (i, (name, count)) in REQUIRED.iter().enumerate() {
        let problem = match s.header.get(i) {
            Some(r) if r.keyword == *name && r.params.len() == *count => continue,
            Some(r) if r.keyword == *name => format!(
                "{name} has {} attributes, the header entity has {count}",
                r.params.len()
            ),
            found => format!(
                "header entity {} should be {name}, found {}: the header starts with FILE_DESCRIPTION, FILE_NAME and FILE_SCHEMA, in this order",
                i + 1,
                found.map_or("nothing", |r| r.keyword)
            ),
        };
        diags.push(Diagnostic::error("step.header", problem, location.clone()));
    }
}

/// What the conformance check ([`ImportOptions::conformance`]) adds to reading, over every
/// instance of the DATA section (ISO 10303-21 clause 10), not only those the geometry
/// needs: each instance syntactically complete (an empty `#17 = ;` is an error), each
/// simple instance of an entity the schema tables know with its EXPRESS attribute count,
/// each reference naming an instance of the file, of an entity type its attribute allows
/// where the tables declare it (`REFERENCE_TYPES`), and no instance referring to itself
/// through any chain of references.
fn conformance(
    s: &Scanned<'_>,
    diags: &mut Vec<Diagnostic>,
    cancel: &crate::exchange::Cancel,
) -> Result<(), Diagnostic> {
    let mut ids = Vec::with_capacity(s.instances.len());
    for (k, raw) in s.instances.iter().enumerate() {
        if k % crate::exchange::READ_POLL == 0 {
            cancel.stop_read()?;
        }
        if s.get(raw.id).map(|r| r.offset()) != Some(raw.offset()) {
            continue; // a duplicated id, reported by the scan
        }
        ids.push(raw.id);
        let inst = match s.decode(raw) {
            Ok(inst) => inst,
            Err(e) => {
                diags.push(parse_diagnostic(&e));
                continue;
            }
        };
        let mut dangling = Vec::new();
        nurbsx_parsers::step::for_each_reference(&inst.body, |id| {
            if s.get(id).is_none() && !dangling.contains(&id) {
                dangling.push(id);
            }
        });
        for id in dangling {
            diags.push(parse_diagnostic(&s.error_at(
                ParseErrorKind::DanglingReference(id),
                raw.offset(),
                Some(raw.id),
            )));
        }
        let known = match &inst.body {
            nurbsx_parsers::step::Body::Simple(r) => SUPERTYPE_CHAINS
                .iter()
                .any(|(e, _)| *e == canonical_name(r.keyword)),
            nurbsx_parsers::step::Body::Complex(_) => true,
        };
        if known {
            match Attributes::of(&inst, s.at(raw)) {
                Ok(a) => diags.extend(s.reference_type_errors(&a).iter().map(|e| Diagnostic {
                    code: "step.reference.type".to_owned(),
                    ..schema_diagnostic(e)
                })),
                Err(e) => diags.push(schema_diagnostic(&e)),
            }
        }
    }
    diags.extend(s.find_cycles(ids).iter().map(parse_diagnostic));
    Ok(())
}

/// Which of the reader's lists may take an instance: [`maybe_bspline`], [`maybe_product`]
/// and [`maybe_geometry`] of it.
#[derive(Debug, Clone, Copy)]
struct Class {
    bspline: bool,
    product: bool,
    geometry: bool,
}

/// Slots of [`Classes`] (a power of two).
const CLASS_SLOTS: usize = 256;

/// The [`Class`] of the instances met so far by their keyword (a simple instance) or whole
/// body (a complex one), in a table of recent texts: a file has a few dozen keywords and
/// complex instances repeated thousands of times (Open CASCADE writes one 2-D context per
/// pcurve), each classified once instead of once per instance. A text whose slot holds
/// another is classified again, with the same answer.
struct Classes<'t> {
    slots: Vec<Option<(&'t str, Class)>>,
}

impl Default for Classes<'_> {
    fn default() -> Self {
        Classes {
            slots: vec![None; CLASS_SLOTS],
        }
    }
}

impl<'t> Classes<'t> {
    fn of(&mut self, text: &'t str, raw: &RawInstance<'t>) -> Class {
        let key = raw.keyword(text).unwrap_or_else(|| raw.body(text));
        let b = key.as_bytes();
        // The first and last 8 bytes and the length (a long B-spline body is not read
        // whole to find its slot).
        let word = |x: &[u8]| {
            let mut w = [0u8; 8];
            let n = x.len().min(8);
            w[..n].copy_from_slice(&x[..n]);
            u64::from_le_bytes(w)
        };
        let h = (word(b) ^ word(&b[b.len().saturating_sub(8)..]).rotate_left(29) ^ b.len() as u64)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let slot = (h >> 56) as usize % self.slots.len().max(1);
        if let Some(Some((k, c))) = self.slots.get(slot) {
            if *k == key {
                return *c;
            }
        }
        let c = Class {
            bspline: maybe_bspline(text, raw),
            product: maybe_product(text, raw),
            geometry: maybe_geometry(text, raw),
        };
        if let Some(s) = self.slots.get_mut(slot) {
            *s = Some((key, c));
        }
        c
    }
}

/// Cheap keyword test before decoding: simple instances by keyword, complex ones by a
/// substring search of their body.
fn maybe_bspline(text: &str, raw: &RawInstance<'_>) -> bool {
    // Every name below starts with B, U or Q: most instances (points, directions, topology)
    // are rejected by their first letter, which the scanner kept (no read of the text).
    if raw
        .keyword_initial()
        .is_some_and(|c| !matches!(c, b'B' | b'U' | b'Q'))
    {
        return false;
    }
    match raw.keyword(text) {
        // (A keyword with lower-case letters is a syntax error, ISO 10303-21 6.4, that the
        // scanner itself reports: such a statement never becomes a `RawInstance`.)
        Some(k) => matches!(
            canonical_name(k),
            "B_SPLINE_CURVE_WITH_KNOTS"
                | "BEZIER_CURVE"
                | "UNIFORM_CURVE"
                | "QUASI_UNIFORM_CURVE"
                | "B_SPLINE_CURVE"
                | "B_SPLINE_SURFACE_WITH_KNOTS"
                | "BEZIER_SURFACE"
                | "UNIFORM_SURFACE"
                | "QUASI_UNIFORM_SURFACE"
                | "B_SPLINE_SURFACE"
        ),
        // A simple instance whose keyword starts lower-case has no keyword here (the
        // scanner only takes upper-case ones); decode it so the syntax error is reported.
        None if raw.body(text).starts_with(|c: char| c.is_ascii_lowercase()) => true,
        // A complex instance: one of the B-spline partials, long or short form, upper or
        // lower case. Found from the `B`/`b` bytes (one SIMD pass): most complex instances
        // of a file are representation contexts, with none.
        None => {
            let b = raw.body(text).as_bytes();
            memchr::memchr2_iter(b'B', b'b', b).any(|i| {
                let rest = b.get(i..).unwrap_or_default();
                [
                    &b"B_SPLINE_"[..],
                    b"BSPCR",
                    b"BSCWK",
                    b"BSSWK",
                    b"b_spline_",
                ]
                .iter()
                .any(|n| rest.starts_with(n))
            })
        }
    }
}

/// Cheap keyword test for the product structure (`assembly.rs`): simple instances by
/// keyword, complex ones by a substring search of their body.
#[inline]
fn maybe_product(text: &str, raw: &RawInstance<'_>) -> bool {
    match raw.keyword(text) {
        Some(k) => is_product_entity(k),
        None => maybe_complex_product(raw.body(text)),
    }
}

/// Cheap keyword test for the other geometry and topology entities (`geometry.rs`):
/// simple instances by keyword, every complex instance (few, and the decoder ignores those
/// without a geometry partial).
#[inline]
fn maybe_geometry(text: &str, raw: &RawInstance<'_>) -> bool {
    match raw.keyword(text) {
        Some(k) => is_geometry_entity(k),
        None => maybe_complex_geometry(raw.body(text)),
    }
}

/// Radians per unit of the file's plane angle (ISO 10303-41 plane_angle_unit of the
/// representation context), recorded in `doc`'s diagnostics; radians when none is declared.
fn plane_angle(s: &Scanned<'_>, contexts: &[&RawInstance<'_>], doc: &mut Document) -> f64 {
    let (found, problems) = context_plane_angle(s, contexts);
    for (id, offset, m) in problems {
        let (line, column) = s.locate(offset);
        doc.diagnostics.push(Diagnostic::warning(
            "units_unknown",
            m,
            Location {
                line: Some(line),
                column: Some(column),
                entity: Some(super::instance_label(id).into()),
                ..Location::default()
            },
        ));
    }
    match found {
        Some((_, a)) => {
            if a.radians != 1.0 {
                doc.diagnostics.push(Diagnostic::info(
                    "units",
                    format!(
                        "plane-angle unit {} ({} rad): angles converted to radians",
                        a.label, a.radians
                    ),
                    Location::default(),
                ));
            }
            a.radians
        }
        None => {
            doc.diagnostics.push(Diagnostic::warning(
                "units_missing",
                "no representation context assigns a plane-angle unit; radians assumed for conic parameters and angles",
                Location::default(),
            ));
            1.0
        }
    }
}

/// A schema error (attributes that do not match the entity's declaration) as a diagnostic.
fn schema_diagnostic(e: &SchemaError) -> Diagnostic {
    Diagnostic::error(
        "step.schema",
        e.detail(),
        Location {
            line: Some(e.line),
            column: Some(e.column),
            entity: Some(super::instance_label(e.entity).into()),
            ..Location::default()
        },
    )
}

/// A parse error as a diagnostic.
fn parse_diagnostic(e: &ParseError) -> Diagnostic {
    let loc = Location {
        line: Some(e.line),
        column: Some(e.column),
        entity: e.entity.map(|e| super::instance_label(e).into()),
        ..Location::default()
    };
    match &e.kind {
        ParseErrorKind::SkippedSection(_) => {
            Diagnostic::warning("step.structure", e.kind.to_string(), loc)
        }
        ParseErrorKind::DuplicateId { .. }
        | ParseErrorKind::TrailingGarbage
        | ParseErrorKind::Missing(_) => {
            Diagnostic::error("step.structure", e.kind.to_string(), loc)
        }
        ParseErrorKind::ReferenceCycle(_) => {
            Diagnostic::error("step.reference_cycle", e.kind.to_string(), loc)
        }
        ParseErrorKind::LowercaseKeyword(_) => {
            Diagnostic::error(LOWER_CASE_KEYWORD, e.kind.to_string(), loc)
        }
        ParseErrorKind::DanglingReference(_) => {
            Diagnostic::error("step.reference", e.kind.to_string(), loc)
        }
        // Resource limits get the `limit.*` codes the pipeline and IGES reader use, so a
        // caller can tell "too big for this configuration" from "malformed".
        ParseErrorKind::NestingTooDeep(_) => {
            Diagnostic::error("limit.nesting_depth", e.kind.to_string(), loc)
        }
        ParseErrorKind::TooManyParameters(_) => {
            Diagnostic::error("limit.params_per_entity", e.kind.to_string(), loc)
        }
        ParseErrorKind::TooManyInstances(_) => {
            Diagnostic::error("limit.entities", e.kind.to_string(), loc)
        }
        ParseErrorKind::InputTooLarge { .. } => {
            Diagnostic::error("limit.input_bytes", e.kind.to_string(), loc)
        }
        _ => Diagnostic::error("step.syntax", e.kind.to_string(), loc),
    }
}

/// Finds the file's length unit, records it in `doc`, and returns the factor to apply to
/// coordinates (1 unless a conversion is needed) and the file's largest length uncertainty
/// in the model's unit (0 when it declares none).
fn file_units(
    s: &Scanned<'_>,
    contexts: &[&RawInstance<'_>],
    options: &ImportOptions,
    doc: &mut Document,
) -> (f64, f64) {
    let (found, problems, uncertainties) = context_units(s, contexts);
    let loc = |id: u64, offset: usize| {
        let (line, column) = s.locate(offset);
        Location {
            line: Some(line),
            column: Some(column),
            entity: Some(super::instance_label(id).into()),
            ..Location::default()
        }
    };
    for (id, offset, m) in &problems {
        doc.diagnostics.push(Diagnostic::warning(
            "units_unknown",
            m.clone(),
            loc(*id, *offset),
        ));
    }
    let offset_of = |id: u64| s.get(id).map_or(0, |r| r.offset());
    let chosen: Option<(u64, FileUnit)> = found.first().cloned();
    let mut distinct: Vec<&(u64, FileUnit)> = Vec::new();
    for f in &found {
        if !distinct.iter().any(|d| d.1.mm == f.1.mm) {
            distinct.push(f);
        }
    }
    if distinct.len() > 1 {
        let list = distinct
            .iter()
            .map(|(id, u)| format!("#{id}: {} ({} mm)", u.label, u.mm))
            .collect::<Vec<_>>()
            .join(", ");
        if let Some((id, u)) = &chosen {
            doc.diagnostics.push(Diagnostic::warning(
                "units_ambiguous",
                format!("representation contexts declare different length units ({list}); all coordinates are read in the first, {}", u.label),
                loc(*id, offset_of(*id)),
            ));
        }
    }
    let mut scale = 1.0;
    let (mut unit, label) = match &chosen {
        None => {
            doc.diagnostics.push(Diagnostic::warning(
                "units_missing",
                "no representation context assigns a length unit; millimetres assumed (as Open CASCADE)",
                Location::default(),
            ));
            (LengthUnit::Mm, "MILLI METRE (assumed)".to_owned())
        }
        Some((id, fu)) => {
            if let Some(n) = &fu.note {
                doc.diagnostics.push(Diagnostic::warning(
                    "units_unknown",
                    n.clone(),
                    loc(*id, offset_of(*id)),
                ));
            }
            match fu.unit {
                Some(u) => (u, fu.label.clone()),
                None => {
                    scale = fu.mm;
                    doc.diagnostics.push(Diagnostic::info(
                        "units_converted",
                        format!(
                            "file length unit {} ({} mm) has no named equivalent; coordinates converted to mm",
                            fu.label, fu.mm
                        ),
                        loc(*id, offset_of(*id)),
                    ));
                    (LengthUnit::Mm, fu.label.clone())
                }
            }
        }
    };
    match options.target_units {
        Some(t) if t != unit => {
            scale *= unit.to_mm() / t.to_mm();
            doc.diagnostics.push(Diagnostic::info(
                "units_converted",
                format!(
                    "coordinates converted from {} to {} (factor {})",
                    unit.short_name(),
                    t.short_name(),
                    unit.to_mm() / t.to_mm()
                ),
                Location::default(),
            ));
            unit = t;
        }
        _ => doc.diagnostics.push(Diagnostic::info(
            "units",
            format!("length unit {} ({label})", unit.short_name()),
            Location::default(),
        )),
    }
    doc.units = unit;
    // The largest length uncertainty, in the model's unit: the topology's tolerance is at
    // least this (ISO 10303-43: points closer than it are the same point).
    let uncertainty = uncertainties.into_iter().fold(0.0_f64, f64::max) / unit.to_mm();
    (scale, uncertainty)
}

/// What reading one B-spline needs.
struct Ctx<'s, 'a> {
    s: &'s Scanned<'a>,
    raw: &'s RawInstance<'a>,
    options: &'s ImportOptions,
    scale: f64,
}

impl<'a> Ctx<'_, 'a> {
    fn location(&self) -> Location {
        let (line, column) = self.s.locate(self.raw.offset());
        Location {
            line: Some(line),
            column: Some(column),
            entity: Some(super::instance_label(self.raw.id).into()),
            ..Location::default()
        }
    }

    fn error(&self, code: &str, message: impl Into<String>) -> Diagnostic {
        Diagnostic::error(code, message, self.location())
    }

    fn degree(&self, d: i64, what: &str) -> Result<usize, Diagnostic> {
        let max = self.options.limits.max_degree;
        match usize::try_from(d) {
            Ok(v) if v >= 1 && v <= max => Ok(v),
            Ok(v) if v > max => Err(self.error(
                "limit.degree",
                format!("{what} {v} is above the limit of {max}"),
            )),
            _ => Err(self.error("geometry.invalid", format!("{what} {d} must be at least 1"))),
        }
    }

    /// Resolves control point references to coordinates (scaled), checking one dimension.
    fn points(&self, ids: &[u64], dim: &mut Option<usize>) -> Result<Vec<Point3>, Diagnostic> {
        let max = self.options.limits.max_poles;
        if ids.len() > max {
            return Err(self.error(
                "limit.poles",
                format!("{} control points, above the limit of {max}", ids.len()),
            ));
        }
        let mut out = Vec::with_capacity(ids.len());
        for (i, &id) in ids.iter().enumerate() {
            let Some(praw) = self.s.get(id) else {
                return Err(self.error(
                    "step.reference",
                    format!(
                        "control point {} references #{id}, which is not defined",
                        i + 1
                    ),
                ));
            };
            let (c, n) = match self.s.cartesian_point(praw) {
                Ok(point) => point,
                Err(DecodeError::Syntax(e)) => return Err(parse_diagnostic(&e)),
                Err(DecodeError::Schema(e)) => return Err(self.point_error(i, id, &e.detail())),
            };
            match *dim {
                None if n == 2 || n == 3 => *dim = Some(n),
                None => {
                    return Err(self.error(
                        "points.invalid",
                        format!(
                            "control point {} (#{id}) has {n} coordinate(s); 2 or 3 expected",
                            i + 1
                        ),
                    ));
                }
                Some(d) if d != n => {
                    return Err(self.error(
                        "points.invalid",
                        format!(
                            "control point {} (#{id}) has {n} coordinates, the first has {d}",
                            i + 1
                        ),
                    ));
                }
                Some(_) => {}
            }
            out.push([c[0] * self.scale, c[1] * self.scale, c[2] * self.scale]);
        }
        Ok(out)
    }

    /// A control point that is not a CARTESIAN_POINT: a reference cycle if one goes
    /// through this B-spline, else a type error.
    fn point_error(&self, index: usize, id: u64, detail: &str) -> Diagnostic {
        if let Some(cycle) = self.s.find_cycles([self.raw.id]).into_iter().next() {
            return Diagnostic::error(
                "step.reference_cycle",
                cycle.kind.to_string(),
                self.location(),
            );
        }
        self.error(
            "step.reference",
            format!(
                "control point {} (#{id}) is not a usable CARTESIAN_POINT: {detail}",
                index + 1
            ),
        )
    }

    /// Flat knots for one direction.
    fn knots(
        &self,
        spec: &KnotSpec<'_>,
        dir: usize,
        degree: usize,
        poles: usize,
        what: &str,
        diags: &mut Vec<Diagnostic>,
    ) -> Result<Vec<f64>, Diagnostic> {
        let form = match spec {
            KnotSpec::Explicit {
                multiplicities,
                knots,
                ..
            } => {
                let (Some(m), Some(k)) = (multiplicities.get(dir), knots.get(dir)) else {
                    return Err(self.error("knots.invalid", format!("{what}: no knots")));
                };
                if m.len() != k.len() {
                    return Err(self.error(
                        "knots.invalid",
                        format!("{what}: {} multiplicities for {} knots", m.len(), k.len()),
                    ));
                }
                let mut sum: usize = 0;
                for (i, &v) in m.iter().enumerate() {
                    let mv = usize::try_from(v).ok().filter(|&x| x >= 1).ok_or_else(|| {
                        self.error(
                            "knots.invalid",
                            format!("{what}: multiplicity {} is {v}; must be at least 1", i + 1),
                        )
                    })?;
                    sum = sum.checked_add(mv).ok_or_else(|| {
                        self.error(
                            "knot_count_mismatch",
                            format!("{what}: multiplicities overflow"),
                        )
                    })?;
                }
                let need = poles
                    .checked_add(degree)
                    .and_then(|x| x.checked_add(1))
                    .unwrap_or(usize::MAX);
                if sum != need {
                    return Err(self.error(
                        "knot_count_mismatch",
                        format!(
                            "{what}: multiplicities sum to {sum}, but {poles} control points of degree {degree} need {need}"
                        ),
                    ));
                }
                // Every multiplicity is at least 1 and their sum fits: read them as counts.
                let mults = || m.iter().map(|&v| usize::try_from(v).unwrap_or(0));
                let rule = "ISO 10303-42 function constraints_param_b_spline";
                match knot_rules(k, mults(), degree) {
                    Ok(None) => {}
                    Ok(Some(m)) => diags.push(Diagnostic::nonconforming(
                        "knots.repeated",
                        format!(
                            "{what}: {m} ({rule}); read as one knot of the summed multiplicity"
                        ),
                        self.location(),
                    )),
                    Err(m) => {
                        return Err(self.error("knots.invalid", format!("{what}: {m} ({rule})")));
                    }
                }
                return crate::nurbs::knots::from_distinct(k, mults()).ok_or_else(|| {
                    self.error("knots.invalid", format!("{what}: knot lists do not match"))
                });
            }
            KnotSpec::Bezier => KnotForm::Bezier,
            KnotSpec::Uniform => KnotForm::Uniform,
            KnotSpec::QuasiUniform => KnotForm::QuasiUniform,
        };
        implicit_knots(form, degree, poles)
            .map_err(|m| self.error("knots.invalid", format!("{what}: {m}")))
    }

    /// The form and the knot type of a B-spline as the model keeps them (`Meta::form`,
    /// `Meta::knot_spec`), each checked against its enumeration ([`enumeration`]).
    fn enumerations(
        &self,
        spec: &KnotSpec<'_>,
        form: &str,
        form_name: &str,
        forms: &[&'static str],
        diags: &mut Vec<Diagnostic>,
    ) -> (Cow<'static, str>, Cow<'static, str>) {
        let at = || self.location();
        let form = enumeration(form, forms, form_name, at, diags);
        let knot_spec = match spec {
            KnotSpec::Explicit { knot_spec, .. } => {
                enumeration(knot_spec, KNOT_TYPES, "knot_spec", at, diags)
            }
            KnotSpec::Bezier => Cow::Borrowed("bezier"),
            KnotSpec::Uniform => Cow::Borrowed("uniform"),
            KnotSpec::QuasiUniform => Cow::Borrowed("quasi_uniform"),
        };
        (form, knot_spec)
    }

    fn meta_common(
        &self,
        name: Option<&nurbsx_parsers::step::StepString<'_>>,
        knot_spec: Cow<'static, str>,
    ) -> Meta {
        Meta {
            name: name
                .map(|n| n.decode_lossy().into_owned())
                .filter(|n| !n.is_empty()),
            knot_spec: Some(knot_spec),
            ..Meta::default()
        }
    }

    /// `meta.shape` from a B-spline's `curve_form` / `surface_form` (`form`) when it names a
    /// kind nurbsx checks (ISO 10303-42 clause 4.3 `b_spline_curve_form`,
    /// `b_spline_surface_form`: the conic arcs and the planar, quadric, revolved, extruded
    /// and ruled surfaces) and the geometry passes that kind's check
    /// (`exchange::iges::checked_label`), so that a circle read from STEP is a circle in IGES
    /// output too (form 2); a label the geometry does not have is a `form_mismatch` warning.
    /// `.POLYLINE_FORM.` is checked when written; `.UNSPECIFIED.`, `.QUADRIC_SURF.` and
    /// `.GENERALISED_CONE.` name no kind. The digits the file wrote are those of the poles
    /// before the unit factor (`scale`) multiplied them.
    fn label(&self, form: &str, geometry: &Geometry, meta: &mut Meta, diags: &mut Vec<Diagnostic>) {
        let Some(shape) = super::write::form_shape(form).filter(|s| {
            !matches!(
                s,
                crate::exchange::Shape::Line | crate::exchange::Shape::Polyline
            )
        }) else {
            return;
        };
        let scale = self.scale;
        let written = || {
            let (points, weights) = match geometry {
                Geometry::Curve(c) => (c.control_points(), c.weights()),
                Geometry::Surface(s) => (
                    s.control_points().as_slice(),
                    s.weights().map(|w| w.as_slice()),
                ),
            };
            let file: Vec<Point3> = points.iter().map(|p| p.map(|c| c / scale)).collect();
            4.0 * scale.abs()
                * crate::exchange::iges::written_point_rounding(&file, weights.unwrap_or_default())
        };
        let label = || {
            format!(
                "{} .{}.",
                match geometry {
                    Geometry::Curve(_) => "curve_form",
                    Geometry::Surface(_) => "surface_form",
                },
                form.to_ascii_uppercase()
            )
        };
        (meta.shape, meta.shape_tolerance) = crate::exchange::iges::checked_label(
            shape,
            label,
            geometry,
            &self.location(),
            diags,
            written,
        );
    }

    /// A curve entity from its typed record.
    fn curve_record(
        &self,
        r: BSplineCurve<'_>,
        diags: &mut Vec<Diagnostic>,
    ) -> Result<Entity, Diagnostic> {
        let degree = self.degree(r.degree, "degree")?;
        let mut dim = None;
        let points = self.points(&r.control_points, &mut dim)?;
        let knots = self.knots(&r.knots, 0, degree, points.len(), "knots", diags)?;
        if let Some(w) = &r.weights {
            check_weights(w.iter().copied(), points.len())
                .map_err(|m| self.error("weights.invalid", m))?;
        }
        let curve =
            NurbsCurve::with_dimension(degree, knots, points, r.weights.clone(), dim.unwrap_or(3))
                .map_err(|e| self.error("geometry.invalid", e.to_string()))?;
        let (form, knot_spec) =
            self.enumerations(&r.knots, r.curve_form, "curve_form", CURVE_FORMS, diags);
        let mut meta = self.meta_common(r.name.as_ref(), knot_spec);
        meta.form = Some(form);
        meta.closed_u = r.closed_curve.as_bool();
        meta.self_intersect = r.self_intersect.as_bool();
        if let Some(flag) = r.closed_curve.as_bool() {
            let (a, b) = curve.domain();
            let gap = distance(curve.point_at_unchecked(a), curve.point_at_unchecked(b));
            let tol = closure_tolerance(curve.control_points());
            if flag != (gap <= tol) {
                diags.push(flag_mismatch(
                    flag,
                    format!(
                        "closed_curve is {} but the curve's end points are {gap:e} apart (tolerance {tol:e}); flag kept as information, geometry unchanged",
                        logical_text(r.closed_curve)
                    ),
                    self.location(),
                ));
            }
        }
        let geometry = Geometry::Curve(curve);
        self.label(r.curve_form, &geometry, &mut meta, diags);
        Ok(Entity {
            id: super::instance_label(self.raw.id),
            geometry,
            source: Source {
                entity: r.entity_type,
                line: Some(self.s.line(self.raw.offset())),
            },
            meta,
        })
    }

    /// A surface entity from its typed record.
    fn surface_record(
        &self,
        r: BSplineSurface<'_>,
        diags: &mut Vec<Diagnostic>,
    ) -> Result<Entity, Diagnostic> {
        let du = self.degree(r.u_degree, "u_degree")?;
        let dv = self.degree(r.v_degree, "v_degree")?;
        let nu = r.control_points.len();
        let nv = r.control_points.first().map_or(0, Vec::len);
        if let Some((row, l)) = r
            .control_points
            .iter()
            .enumerate()
            .find(|(_, l)| l.len() != nv)
        {
            return Err(self.error(
                "points.invalid",
                format!(
                    "control_points_list row {} has {} points, row 1 has {nv}",
                    row + 1,
                    l.len()
                ),
            ));
        }
        let total = nu.saturating_mul(nv);
        if total > self.options.limits.max_poles {
            return Err(self.error(
                "limit.poles",
                format!(
                    "{nu} x {nv} control points, above the limit of {}",
                    self.options.limits.max_poles
                ),
            ));
        }
        let flat: Vec<u64> = r.control_points.iter().flatten().copied().collect();
        let mut dim = None;
        let points = self.points(&flat, &mut dim)?;
        let ku = self.knots(&r.knots, 0, du, nu, "u knots", diags)?;
        let kv = self.knots(&r.knots, 1, dv, nv, "v knots", diags)?;
        let weights = match &r.weights {
            None => None,
            Some(w) => {
                if w.len() != nu || w.iter().any(|row| row.len() != nv) {
                    return Err(self.error(
                        "weights.invalid",
                        format!(
                            "weights_data has {} rows of lengths {:?}; the net is {nu} x {nv}",
                            w.len(),
                            w.iter().map(Vec::len).collect::<Vec<_>>()
                        ),
                    ));
                }
                let flat_w: Vec<f64> = w.iter().flatten().copied().collect();
                check_weights(flat_w.iter().copied(), total)
                    .map_err(|m| self.error("weights.invalid", m))?;
                Grid::from_u_major(nu, nv, flat_w)
            }
        };
        let net = Grid::from_u_major(nu, nv, points)
            .ok_or_else(|| self.error("points.invalid", "control net shape"))?;
        let surface = NurbsSurface::with_dimension(du, dv, ku, kv, net, weights, dim.unwrap_or(3))
            .map_err(|e| self.error("geometry.invalid", e.to_string()))?;
        let (form, knot_spec) = self.enumerations(
            &r.knots,
            r.surface_form,
            "surface_form",
            SURFACE_FORMS,
            diags,
        );
        let mut meta = self.meta_common(r.name.as_ref(), knot_spec);
        meta.form = Some(form);
        meta.closed_u = r.u_closed.as_bool();
        meta.closed_v = r.v_closed.as_bool();
        meta.self_intersect = r.self_intersect.as_bool();
        let tol = closure_tolerance(surface.control_points().as_slice());
        let ((u0, u1), (v0, v1)) = surface.domain();
        for (flag, name, is_u) in [
            (r.u_closed, "u_closed", true),
            (r.v_closed, "v_closed", false),
        ] {
            let Some(f) = flag.as_bool() else { continue };
            let mut gap: f64 = 0.0;
            for k in 0..=8 {
                let t = k as f64 / 8.0;
                let (a, b) = if is_u {
                    let v = v0 + (v1 - v0) * t;
                    (
                        surface.point_at_unchecked(u0, v),
                        surface.point_at_unchecked(u1, v),
                    )
                } else {
                    let u = u0 + (u1 - u0) * t;
                    (
                        surface.point_at_unchecked(u, v0),
                        surface.point_at_unchecked(u, v1),
                    )
                };
                gap = gap.max(distance(a, b));
                if !f && gap > tol {
                    // Already known to be open, which agrees with the flag: no message
                    // will need the full maximum (most surfaces take this exit at k = 0).
                    break;
                }
            }
            if f != (gap <= tol) {
                diags.push(flag_mismatch(
                    f,
                    format!(
                        "{name} is {} but opposite boundaries are up to {gap:e} apart (tolerance {tol:e}); flag kept as information, geometry unchanged",
                        logical_text(flag)
                    ),
                    self.location(),
                ));
            }
        }
        let geometry = Geometry::Surface(surface);
        self.label(r.surface_form, &geometry, &mut meta, diags);
        Ok(Entity {
            id: super::instance_label(self.raw.id),
            geometry,
            source: Source {
                entity: r.entity_type,
                line: Some(self.s.line(self.raw.offset())),
            },
            meta,
        })
    }
}

/// A `flag_mismatch` diagnostic. A flag claiming closure the geometry does not have is a
/// warning (readers that act on it, as Open CASCADE does for `closed_curve`, get it wrong);
/// `.F.` on geometry that happens to close is common in real files (Open CASCADE 6.x wrote
/// it for every closed edge curve) and harmless, so it is reported as information.
fn flag_mismatch(flag: bool, message: String, location: Location) -> Diagnostic {
    if flag {
        Diagnostic::warning("flag_mismatch", message, location)
    } else {
        Diagnostic::info("flag_mismatch", message, location)
    }
}

fn logical_text(l: Logical) -> &'static str {
    match l {
        Logical::True => ".T.",
        Logical::False => ".F.",
        Logical::Unknown => ".U.",
    }
}

/// Weight count and positivity (ISO 10303-42 rational_b_spline_curve WR1/WR2).
/// The rules of ISO 10303-42 function constraints_param_b_spline (a WHERE rule of
/// B_SPLINE_CURVE_WITH_KNOTS, and of each direction of B_SPLINE_SURFACE_WITH_KNOTS) that
/// the sum check does not cover: the distinct knots
/// strictly increasing (knots may not repeat a value: a repeated value is a multiplicity),
/// the end multiplicities at most degree + 1 and the interior ones at most the degree.
///
/// A knot that decreases, or a multiplicity above its bound, is an error (the entity is not
/// loaded); a value written twice in a row (`Ok(Some(..))`) has one meaning, that knot with
/// the summed multiplicity, and is non-conforming. The bounds apply to the summed
/// multiplicities.
fn knot_rules(
    knots: &[f64],
    mults: impl Iterator<Item = usize>,
    degree: usize,
) -> Result<Option<String>, String> {
    // The order first: a decreasing knot is the error, whatever the multiplicities.
    let mut repeated = None;
    let mut runs = usize::from(!knots.is_empty());
    for (i, w) in knots.windows(2).enumerate() {
        if w[1] < w[0] {
            return Err(format!(
                "knot {} ({}) is less than knot {} ({}); the distinct knots must strictly increase",
                i + 2,
                w[1],
                i + 1,
                w[0]
            ));
        }
        if w[1] == w[0] {
            repeated.get_or_insert_with(|| {
                format!(
                    "knot {} repeats the value of knot {} ({}); the distinct knots must strictly increase",
                    i + 2,
                    i + 1,
                    w[0]
                )
            });
        } else {
            runs += 1;
        }
    }
    if knots.len() < 2 {
        return Ok(repeated);
    }
    // Then each run of equal knots, read as one knot of the summed multiplicity, against
    // its bound.
    let bound = |i: usize, m: usize| multiplicity_bound(i, runs, m, degree);
    let (mut run, mut sum, mut previous) = (0, 0, None);
    for (&value, m) in knots.iter().zip(mults) {
        if previous.is_some_and(|p| p != value) {
            bound(run, sum)?;
            run += 1;
            sum = 0;
        }
        sum += m;
        previous = Some(value);
    }
    bound(run, sum)?;
    Ok(repeated)
}

/// Multiplicity `m` of distinct knot `i` of `count` against its bound: at most
/// `degree + 1` at the ends, `degree` inside (ISO 10303-42 constraints_param_b_spline).
fn multiplicity_bound(i: usize, count: usize, m: usize, degree: usize) -> Result<(), String> {
    let end = i == 0 || i + 1 == count;
    let max = if end { degree + 1 } else { degree };
    if m > max {
        return Err(format!(
            "{} multiplicity {} is {m}, above {max} (degree {degree})",
            if end { "end" } else { "interior" },
            i + 1
        ));
    }
    Ok(())
}

/// `value`, an enumeration value, in lower case as the model keeps it: the entry of `known`
/// (ISO 10303-42 `knot_type`, `b_spline_curve_form` or `b_spline_surface_form`, in lower
/// case) it names, borrowed, else a lower-cased copy. A value outside them is
/// non-conforming, and reported; the geometry does not depend on it. `location` is asked
/// for only when there is something to say (finding a line counts the lines before the
/// instance).
fn enumeration(
    value: &str,
    known: &[&'static str],
    what: &str,
    location: impl FnOnce() -> Location,
    diags: &mut Vec<Diagnostic>,
) -> Cow<'static, str> {
    if let Some(k) = known.iter().find(|k| k.eq_ignore_ascii_case(value)) {
        return Cow::Borrowed(k);
    }
    diags.push(Diagnostic::nonconforming(
        "step.enumeration",
        format!(
            "{what} .{value}. is not a value of its enumeration ({}); read as UNSPECIFIED",
            known.join(", ").to_ascii_uppercase()
        ),
        location(),
    ));
    Cow::Owned(value.to_ascii_lowercase())
}

/// ISO 10303-42 `knot_type`, in lower case as the model keeps it (`Meta::knot_spec`).
const KNOT_TYPES: &[&str] = &[
    "uniform_knots",
    "quasi_uniform_knots",
    "piecewise_bezier_knots",
    "unspecified",
];

/// ISO 10303-42 `b_spline_curve_form`, in lower case as the model keeps it (`Meta::form`).
const CURVE_FORMS: &[&str] = &[
    "polyline_form",
    "circular_arc",
    "elliptic_arc",
    "parabolic_arc",
    "hyperbolic_arc",
    "unspecified",
];

/// ISO 10303-42 `b_spline_surface_form`, in lower case as the model keeps it.
const SURFACE_FORMS: &[&str] = &[
    "plane_surf",
    "cylindrical_surf",
    "conical_surf",
    "spherical_surf",
    "toroidal_surf",
    "surf_of_revolution",
    "ruled_surf",
    "generalised_cone",
    "quadric_surf",
    "surf_of_linear_extrusion",
    "unspecified",
];

fn check_weights(w: impl ExactSizeIterator<Item = f64>, poles: usize) -> Result<(), String> {
    if w.len() != poles {
        return Err(format!("{} weights for {poles} control points", w.len()));
    }
    for (i, v) in w.enumerate() {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!(
                "weight {} is {v}; weights must be finite and > 0",
                i + 1
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "read_decoder_tests.rs"]
mod decoder_tests;

/// A file written in lower case is read once after its scan: the first reading stops at the
/// scan's finding (no entity decoded), and [`read`] then gives the upper-cased copy's
/// geometry with the finding located.
#[cfg(test)]
mod lower_case_tests {
    use super::*;

    const LOWER: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
        FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\n\
        DATA;\n#1=cartesian_point('',(0.,0.,0.));\n#2=cartesian_point('',(1.,0.,0.));\n\
        #3=B_SPLINE_CURVE_WITH_KNOTS('',1,(#1,#2),.UNSPECIFIED.,.F.,.F.,(2,2),(0.,1.),\
        .UNSPECIFIED.);\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn the_first_reading_of_a_lower_case_file_stops_after_its_scan() {
        let options = ImportOptions::default();
        let first = read_text(LOWER, &options).unwrap();
        assert!(first.entities.is_empty(), "{:?}", first.entities);
        assert_eq!(first.diagnostics.len(), 1, "{:?}", first.diagnostics);
        assert_eq!(first.diagnostics[0].code, LOWER_CASE_KEYWORD);
        let doc = read(LOWER, &options).unwrap();
        assert_eq!(doc.entities.len(), 1, "{:?}", doc.diagnostics);
        let found: Vec<_> = doc
            .diagnostics
            .iter()
            .filter(|d| d.code == LOWER_CASE_KEYWORD)
            .map(|d| (d.location.line, d.location.entity.as_deref()))
            .collect();
        assert_eq!(found, [(Some(8), Some("#1")), (Some(9), Some("#2"))]);
    }
}

/// [`knot_rules`] against the rules read literally (ISO 10303-42
/// constraints_param_b_spline): merge each run of equal knots into one of the summed
/// multiplicity, then bound every merged multiplicity.
#[cfg(test)]
mod knot_rule_tests {
    use proptest::prelude::*;

    use super::{knot_rules, multiplicity_bound};

    /// The rules written out with the merged list.
    fn literal(knots: &[f64], mults: &[usize], degree: usize) -> Result<Option<String>, String> {
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(format!(
                "knot {} ({}) is less than knot {} ({}); the distinct knots must strictly increase",
                i + 2,
                knots[i + 1],
                i + 1,
                knots[i]
            ));
        }
        let repeated = knots.windows(2).position(|w| w[1] == w[0]).map(|i| {
            format!(
                "knot {} repeats the value of knot {} ({}); the distinct knots must strictly increase",
                i + 2,
                i + 1,
                knots[i]
            )
        });
        if knots.len() < 2 {
            return Ok(repeated);
        }
        let mut merged: Vec<(f64, usize)> = Vec::new();
        for (&k, &m) in knots.iter().zip(mults) {
            match merged.last_mut() {
                Some((v, n)) if *v == k => *n += m,
                _ => merged.push((k, m)),
            }
        }
        for (i, &(_, m)) in merged.iter().enumerate() {
            multiplicity_bound(i, merged.len(), m, degree)?;
        }
        Ok(repeated)
    }

    proptest! {
        #[test]
        fn knot_rules_are_the_rules_read_literally(
            steps in prop::collection::vec(-1i8..3, 0..12),
            mults in prop::collection::vec(1usize..6, 12),
            degree in 1usize..5,
        ) {
            // Knots from small steps: rises, repeats and (step -1) decreases.
            let mut knots = Vec::new();
            let mut v = 0.0;
            for s in steps {
                v += f64::from(s);
                knots.push(v);
            }
            let m = &mults[..knots.len()];
            prop_assert_eq!(knot_rules(&knots, m.iter().copied(), degree), literal(&knots, m, degree));
        }
    }
}

#[cfg(test)]
mod pcurve_user_tests {
    use proptest::prelude::*;

    use crate::exchange::Entity;
    use crate::nurbs::{Geometry, NurbsCurve};

    fn entity(id: &str) -> Entity {
        let line = NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![[0.; 3], [1., 0., 0.]], None);
        Entity {
            id: id.into(),
            geometry: Geometry::Curve(line.expect("a line")),
            source: Default::default(),
            meta: Default::default(),
        }
    }

    proptest! {
        /// The labels are those a direct reading of the rule gives: for each entity `#n`,
        /// the edges paired with curve n in the order found, on the first entity so
        /// labelled only; entity ids in any order, repeated, or not instance labels.
        #[test]
        fn each_curve_takes_its_edges_in_the_order_found(
            ids in proptest::collection::vec(0u64..40, 0..30),
            pairs in proptest::collection::vec((0u64..40, 0u64..1000), 0..60),
            odd in proptest::collection::vec(0usize..30, 0..3),
        ) {
            let mut labels: Vec<String> = ids.iter().map(|id| format!("#{id}")).collect();
            for k in odd {
                if let Some(l) = labels.get_mut(k) {
                    *l = format!("D{k}");
                }
            }
            let mut entities: Vec<Entity> = labels.iter().map(|l| entity(l)).collect();
            super::label_pcurve_users(&mut entities, pairs.clone());
            let mut done = std::collections::HashSet::new();
            for (e, label) in entities.iter().zip(&labels) {
                let id = label.strip_prefix('#').and_then(|d| d.parse::<u64>().ok());
                let expected: Vec<String> = match id {
                    Some(id) if done.insert(id) => pairs
                        .iter()
                        .filter(|(curve, _)| *curve == id)
                        .map(|(_, edge)| format!("#{edge}"))
                        .collect(),
                    _ => Vec::new(),
                };
                prop_assert_eq!(&e.meta.used_by, &expected, "{}", label);
            }
        }
    }
}

/// [`Classes`] answers as the three keyword tests it remembers: for every instance of
/// samples with simple and complex instances (B-splines, products, contexts, Open CASCADE's
/// 2-D contexts repeated per pcurve), read twice so that the second pass is answered from
/// the table, and with texts that share a slot.
#[cfg(test)]
mod class_tests {
    use super::*;

    #[test]
    fn remembered_classes_are_the_keyword_tests() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("samples");
        let mut checked = 0;
        for name in [
            "freecad/parts/assembly_links.step",
            "freecad/analytic/torus.step",
            "freecad/brep_filleted_box_nurbs.step",
            "public/autodesk_atf_conical_surface.step",
        ] {
            let text = std::fs::read_to_string(root.join(name)).unwrap();
            let scanned = nurbsx_parsers::step::scan(&text, &Default::default()).unwrap();
            let mut classes = Classes::default();
            for _ in 0..2 {
                for raw in &scanned.instances {
                    let c = classes.of(&text, raw);
                    let expected = (
                        maybe_bspline(&text, raw),
                        maybe_product(&text, raw),
                        maybe_geometry(&text, raw),
                    );
                    assert_eq!(
                        (c.bspline, c.product, c.geometry),
                        expected,
                        "{name} #{}",
                        raw.id
                    );
                    checked += 1;
                }
            }
            // One slot for every text: each lookup meets another text there, or its own.
            let mut crowded = Classes {
                slots: vec![None; 1],
            };
            for raw in scanned.instances.iter().rev() {
                let c = crowded.of(&text, raw);
                let expected = (maybe_product(&text, raw), maybe_geometry(&text, raw));
                assert_eq!((c.product, c.geometry), expected, "{name} #{}", raw.id);
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}
