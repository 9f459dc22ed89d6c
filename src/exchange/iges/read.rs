//! IGES file -> [`Document`]: every curve and surface entity with an exact NURBS form
//! (126, 128 with their flags checked; the analytic entities of [`super::curves`] and
//! [`super::surfaces`]), 124 chains applied to all of them, units reported or converted
//! (spec.md a.2, b.1-b.4; pitfalls.md A4, B11, D20-22).

use std::collections::{BTreeMap, BTreeSet};

use nurbsx_parsers::iges::records::{
    Boundary141, BoundedSurface143, CompositeCurve102, Curve126, CurveOnSurface142, EdgeList504,
    Face510, Loop508, Surface128, Transform124, TrimmedSurface144,
};
use nurbsx_parsers::iges::{self, DirectoryEntry, IgesFile, ParseError, ParseWarning};
use rayon::prelude::*;

use super::analysis;
use super::chain::{self, ChainError};
use super::curves::{self, Composite};
use super::forms;
use super::surfaces;
use super::vector::{compose, dot};
use crate::exchange::{
    Diagnostic, Document, Entity, Format, ImportOptions, LengthUnit, Location, Meta,
    ParameterRange, Source,
};
use crate::nurbs::transform::Affine;
use crate::nurbs::{Geometry, Grid, NurbsCurve, NurbsSurface, Point3};

/// Curve entity types converted (IGES 5.3 sections 4.3-4.14, 4.23).
const CURVE_TYPES: [i64; 7] = [100, 102, 104, 106, 110, 112, 126];

/// Surface entity types converted (sections 4.12, 4.15-4.19, 4.24, 4.50-4.54).
const SURFACE_TYPES: [i64; 11] = [108, 114, 118, 120, 122, 128, 190, 192, 194, 196, 198];

/// Entity types with no exact rational form: one located diagnostic each.
fn inexact(t: i64) -> Option<&'static str> {
    match t {
        125 => Some("a flash (a 2-D shape referenced by a point) is annotation"),
        130 => Some("an offset curve has no exact rational form in general"),
        140 => Some("an offset surface has no exact rational form in general"),
        _ => None,
    }
}

/// What every conversion of one file shares: the file, the options, the unit factor and
/// the maps computed once (parameter-space curves, the faces' boundary curves per surface).
pub(super) struct Context<'f, 'a> {
    pub file: &'f IgesFile<'a>,
    pub options: &'f ImportOptions,
    /// Scale from the file's unit to the document's (`None`: the same unit).
    pub factor: Option<f64>,
    pub parametric: &'f BTreeSet<usize>,
    /// Surface DE -> the model-space boundary curves of the 144s and 510s that use it.
    pub boundaries: &'f BTreeMap<usize, Vec<i64>>,
    /// The 102s that are face boundaries (named by a 142, 504 or 508): their constituents
    /// are that boundary's edges and stay separate curves.
    pub edge_chains: &'f BTreeSet<usize>,
    /// The 402 groups of trimmed faces and the group of each face they list.
    pub face_groups: &'f super::topology::FaceGroups,
}

impl Context<'_, '_> {
    /// The entity's 124 chain composed into one map (`None` when it has none), with
    /// `meta.transforms_applied` set; `None` with a `transform.invalid` error when the
    /// chain cannot be resolved.
    pub fn transforms(
        &self,
        entry: &DirectoryEntry,
        meta: &mut Meta,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Option<Affine>> {
        let ts = transforms(self.file, entry, self.options, meta, diags)?;
        Some(
            ts.iter()
                .map(|t| t.rows)
                .reduce(|inner, outer| compose(&outer, &inner)),
        )
    }

    /// A distance tolerance for values of this size: the relative tolerance of
    /// [`analysis::tolerance`], at least the file's resolution (Global parameter 19).
    pub fn tolerance(&self, values: &[f64]) -> f64 {
        analysis::tolerance_of(values.iter().copied())
            .max(self.file.global.resolution.unwrap_or(0.0))
    }

    /// The tolerance of a check that compares lengths formed from written coordinates (an
    /// arc's two radii, an end point against its conic): [`Context::tolerance`], at least
    /// what the rounding of the digits written allows. Each coordinate is within `e` =
    /// [`analysis::written_rounding`] of the value meant, a plane point within `sqrt 2 e`, a
    /// distance between two points within `2 sqrt 2 e`, and the difference of two such
    /// distances within `4 sqrt 2 e`.
    pub fn written_tolerance(&self, values: &[f64]) -> f64 {
        self.tolerance(values).max(
            4.0 * std::f64::consts::SQRT_2 * analysis::written_rounding(values.iter().copied()),
        )
    }
}

/// Reads every curve and surface entity of an IGES file.
///
/// Returns `Err` only when the file as a whole cannot be read (sections, Global section,
/// directory structure); per-entity problems are error diagnostics in the document, and
/// the other entities still load. Diagnostic codes: `iges.syntax` (file-level),
/// `iges.entity` (an entity's record is unreadable), `geometry.invalid`, `limit.degree`,
/// `limit.poles`, `transform.invalid`, `prop3_inconsistent`, `prop3_rational_equal_weights`,
/// `flag_mismatch`, `flag_invalid`, `missing_param_range`, `param_range_outside`,
/// `missing_normal`, `unit_conflict`, `unit_unknown`, `unit_default`, `units_converted`,
/// `model_scale_ignored`, `trimmed_to_range`, `trim_not_applied`, `trim_ignored` (every trim
/// when read geometry-only, and the surface of a face that could not be read),
/// `topology_ignored`
/// (geometry-only), `entities_skipped`, `no_exact_form`, the topology's codes
/// (`topology.not_read`, `topology.loop_open`, `topology.boundary_surface`, `topology.edge_vertex`,
/// `topology.pcurve_deviates`, `pcurve.not_computed`, `topology.shell_open`,
/// `topology.solid_shell_open`, `topology.wrong_entity`, `topology.geometry_missing`,
/// `topology.no_model_curve`, `topology.vertex_use`, `topology.edge_composite`,
/// `topology.edge_tolerance`, `topology.outer_missing`), the subfigures' codes
/// (`assembly.placed`, `assembly.refused`, `assembly.not_placed`,
/// `assembly.geometry_not_placed`), the conversions' codes
/// (`form_mismatch`, `conic.degenerate`, `conic_point_off`, `arc_radius_mismatch`,
/// `unbounded.not_represented`, `points.not_represented`, `annotation.not_represented`,
/// `vectors_dropped`, `spline_gap`, `spline_terminate`, `composite_gap`,
/// `composite_pieces`, `composite_edges`, `construction_curve`, `composite.nested`, `composite.empty`, `ruled.arc_length`,
/// `ruled.parameterisation`, `pointer.invalid`, `reference.unreadable`), and the parser's
/// warnings (`crlf`, `short_line`, `sequence`, `terminate_count`, `param_line_count`,
/// `delimiter_form`, `global_field`, `missing_start`...).
pub fn read(text: &str, options: &ImportOptions) -> Result<Document, Diagnostic> {
    let cancel = &options.cancel;
    let file = iges::parse_with(text, &options.limits, cancel.scan_stop()).map_err(|e| {
        match e.kind {
            iges::ErrorKind::Stopped => cancel.stop_read().err(),
            _ => None,
        }
        .unwrap_or_else(|| parse_diag("iges.syntax", &e))
    })?;
    cancel.stop_read()?;
    let mut diags: Vec<Diagnostic> = file.warnings.iter().map(warning_diag).collect();
    let file_unit = units(&file, &mut diags);
    let units = options.target_units.unwrap_or(file_unit);
    if units != file_unit {
        diags.push(Diagnostic::info(
            "units_converted",
            format!(
                "coordinates converted from {} (the file's unit) to {} (factor {})",
                file_unit.short_name(),
                units.short_name(),
                file_unit.to_mm() / units.to_mm()
            ),
            global_location(),
        ));
    }
    let factor = if units == file_unit {
        None
    } else {
        Some(file_unit.to_mm() / units.to_mm())
    };
    let users = users(&file);
    let parametric = parameter_space_curves(&file);
    let boundaries = boundaries(&file);
    let members = composite_members(&file);
    let edge_chains = edge_chains(&file);
    let face_groups = super::topology::FaceGroups::of(&file);
    let cx = Context {
        file: &file,
        options,
        factor,
        parametric: &parametric,
        boundaries: &boundaries,
        edge_chains: &edge_chains,
        face_groups: &face_groups,
    };
    let mut doc = Document::new(Format::Iges, units);
    doc.schema = file.global.version_name().map(str::to_owned);
    // Entities decode independently once the file is split and the maps are known:
    // decode them on the rayon threads (`collect` keeps file order), then append the
    // results and their diagnostics in that order, as a sequential loop would.
    let stopped = std::sync::atomic::AtomicBool::new(false);
    let results: Vec<(Outcome, Vec<Diagnostic>)> = file
        .entries
        .par_iter()
        .enumerate()
        .map(|(k, entry)| {
            if cancel.skip(k, &stopped) {
                return (Outcome::Nothing, Vec::new());
            }
            let mut diags = Vec::new();
            let outcome = read_entry(&cx, entry, &users, &members, &mut diags);
            (outcome, diags)
        })
        .collect();
    cancel.stop_read()?;
    let mut skipped: BTreeMap<i64, usize> = BTreeMap::new();
    for (outcome, entry_diags) in results {
        diags.extend(entry_diags);
        match outcome {
            Outcome::Entities(e) => doc.entities.extend(e),
            Outcome::Skipped(t) => *skipped.entry(t).or_default() += 1,
            Outcome::Nothing => {}
        }
    }
    if !skipped.is_empty() {
        let list: Vec<String> = skipped.iter().map(|(t, n)| format!("{n} x {t}")).collect();
        diags.push(Diagnostic::warning(
            "entities_skipped",
            format!(
                "entities that are neither curves nor surfaces (colours, properties, structure, points, annotation) are not carried into the model or its output: {}",
                list.join(", ")
            ),
            Location::default(),
        )
        .not_carried());
    }
    super::topology::read(&cx, &mut doc, &mut diags);
    cancel.stop_read()?;
    directory_fields(&file, options.conformance, &mut diags);
    if options.conformance {
        pointer_conformance(&file, &mut diags);
    }
    // A finding reached by two paths (an entity decoded for itself and for its user) is
    // reported once.
    let mut seen = std::collections::HashSet::new();
    diags.retain(|d| seen.insert((d.code.clone(), d.message.clone(), d.location.to_string())));
    doc.diagnostics = diags;
    Ok(doc)
}

/// The conformance check of every entity's pointers, whether nurbsx converts the entity or
/// not: the DE pointer fields (structure, line font, level, view, transformation matrix,
/// label display, color; IGES 5.3 section 2.2.4.4) and the parameter pointers the entity
/// declarations name (chapter 4, with the associativity and property pointers of section
/// 2.2.4.5.2; for the 322, the 422 and the 406 forms 11 and 27, whose layouts come from
/// their data, the pointers their checkers read) must each name the first (odd) line of an
/// existing directory entry, of an entity type the field allows, and no entity may reach
/// itself through them (back pointers aside, [`back_pointer`]). An entity whose parameters
/// do not decode is reported here too.
fn pointer_conformance(file: &IgesFile<'_>, diags: &mut Vec<Diagnostic>) {
    let count = file.entries.len();
    // Every entity's outgoing pointers (to DE pointers), for the cycle search.
    let mut graph: Vec<Vec<usize>> = vec![Vec::new(); count];
    // The 322 layouts the 422 instances follow, each read once.
    let mut layouts = iges::AttributeLayouts::default();
    for entry in file.entries.iter().flatten() {
        let mut fields: Vec<(&'static str, i64, &'static [i64])> = Vec::new();
        // DE fields that are pointers when negative (section 2.2.4.4.3-5, .13) or positive.
        for (name, value, to, negated) in [
            ("DE structure", entry.structure, &[][..], true),
            ("DE line font pattern", entry.line_font, &[304][..], true),
            ("DE level", entry.level, &[406][..], true),
            ("DE view", entry.view, &[402, 410][..], false),
            (
                "DE transformation matrix",
                entry.transform,
                &[124][..],
                false,
            ),
            (
                "DE label display associativity",
                entry.label_display,
                &[402][..],
                false,
            ),
            ("DE color", entry.color, &[314][..], true),
        ] {
            match (negated, value) {
                (true, v) if v < 0 => fields.push((name, v, to)),
                (false, v) if v > 0 => fields.push((name, v, to)),
                _ => {}
            }
        }
        match file.references_with(entry, &mut layouts) {
            Some(Ok(refs)) => fields.extend(refs),
            Some(Err(e)) => diags.push(parse_diag("iges.entity", &e)),
            None => {}
        }
        for (name, value, to) in fields {
            let p = value.unsigned_abs();
            let target = usize::try_from(p).ok().and_then(|p| {
                (p % 2 == 1)
                    .then(|| file.entries.get(p / 2))
                    .flatten()
                    .map(|t| (p, t))
            });
            let problem = match target {
                None if p % 2 == 0 && p > 0 && p / 2 <= count as u64 => Some(format!(
                    "{name} pointer {value} names the second line of a directory entry; a DE pointer is the odd sequence number of its first line"
                )),
                None => Some(format!(
                    "{name} pointer {value} names no directory entry (the D section has {} lines)",
                    2 * count
                )),
                Some((_, Err(_))) => None, // that entry's own error is reported
                Some((p, Ok(t))) => {
                    if !back_pointer(name) {
                        if let Some(slot) = graph.get_mut(entry.pointer / 2) {
                            slot.push(p);
                        }
                    }
                    (!to.is_empty() && !to.contains(&t.entity_type)).then(|| {
                        format!(
                            "{name} pointer {value} names a {} entity; the field allows {}",
                            t.entity_type,
                            to.iter().map(i64::to_string).collect::<Vec<_>>().join(", ")
                        )
                    })
                }
            };
            if let Some(message) = problem {
                diags.push(Diagnostic::error(
                    "pointer.invalid",
                    message,
                    entity_location(entry),
                ));
            }
        }
    }
    // Cycles, by an iterative depth-first search (no recursion on input data).
    let mut state = vec![0u8; count]; // 0 new, 1 on the path, 2 done
    for root in 0..count {
        if state[root] != 0 {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        state[root] = 1;
        while let Some(&mut (node, ref mut next)) = stack.last_mut() {
            let Some(&p) = graph[node].get(*next) else {
                state[node] = 2;
                stack.pop();
                continue;
            };
            *next += 1;
            let child = p / 2;
            match state.get(child) {
                Some(0) => {
                    state[child] = 1;
                    stack.push((child, 0));
                }
                Some(1) => {
                    let path: Vec<String> = stack
                        .iter()
                        .map(|&(n, _)| n)
                        .skip_while(|&n| n != child)
                        .chain([child])
                        .map(|n| format!("D{}", 2 * n + 1))
                        .collect();
                    if let Some(Ok(e)) = file.entries.get(node) {
                        diags.push(Diagnostic::error(
                            "pointer.cycle",
                            format!("pointer cycle {}", path.join(" -> ")),
                            entity_location(e),
                        ));
                    }
                }
                _ => {}
            }
        }
    }
}

/// Whether a pointer field names an entity that lists the entity holding it, so that the two
/// point at each other by design and the pair is no dependency cycle: the associativity
/// pointers (IGES 5.3 section 2.2.4.5.2, back pointers to the 402 instances, and the
/// text entities in their place, that refer to the entity), the DE view field (section
/// 2.2.4.4.6; a 402 form 3 or 4 Views Visible lists the entities it displays) and the DE
/// label display field (section 2.2.4.4.8; a 402 form 5 Label Display names the entity
/// it labels). Such pointers are still checked for their target's existence and type.
fn back_pointer(field: &str) -> bool {
    matches!(
        field,
        nurbsx_parsers::iges::records::ASSOCIATIVITY_POINTER
            | "DE view"
            | "DE label display associativity"
    )
}

/// The DE fields outside their ranges (IGES 5.3 section 2.2.4.4, see
/// `DirectoryEntry::field_problems`), each at its DE line; and the DE level and label
/// display pointers naming an entity of the right type but the wrong form (a level
/// pointer names a 406 form 1 Definition Levels property, section 2.2.4.4.5; a label
/// display pointer a 402 form 5 Label Display associativity, section 2.2.4.4.8). Non-
/// conforming: the entity is read the same, nothing depends on these fields; except an
/// undefined entity type, whose entity cannot be read (an error). The pointer
/// forms are checked with the other pointers, by the conformance check only.
fn directory_fields(file: &IgesFile<'_>, conformance: bool, diags: &mut Vec<Diagnostic>) {
    let gradations = file.global.line_weight_gradations;
    for e in file.entries.iter().flatten() {
        for p in e.field_problems(gradations) {
            // An entity of an undefined type has no meaning to carry: an error.
            let diagnostic = if p.field == 1 {
                Diagnostic::error
            } else {
                Diagnostic::nonconforming
            };
            diags.push(diagnostic(
                "iges.directory_field",
                format!("DE field {}: {}", p.field, p.message),
                Location {
                    line: Some(e.line + (p.sequence - e.pointer)),
                    sequence: Some(p.sequence),
                    ..entity_location(e)
                },
            ));
        }
        if !conformance {
            continue;
        }
        for (name, value, entity, form, what) in [
            (
                "level",
                0i64.saturating_sub(e.level),
                406,
                1,
                "a Definition Levels property",
            ),
            (
                "label display associativity",
                e.label_display,
                402,
                5,
                "a Label Display associativity",
            ),
        ] {
            let target = usize::try_from(value)
                .ok()
                .filter(|p| p % 2 == 1)
                .and_then(|p| file.entries.get(p / 2));
            if let Some(Ok(t)) = target {
                if t.entity_type == entity && t.form != form {
                    diags.push(Diagnostic::error(
                        "pointer.invalid",
                        format!(
                            "DE {name} pointer names a {entity} of form {}; the field names {what} ({entity} form {form})",
                            t.form
                        ),
                        entity_location(e),
                    ));
                }
            }
        }
    }
}

/// What one directory entry gave.
enum Outcome {
    /// Curves or surfaces (several for a 102 whose pieces do not join).
    Entities(Vec<Entity>),
    /// An entity type that is not converted (counted in `entities_skipped`).
    Skipped(i64),
    /// Nothing (a 124 transform, a 102's constituent, or an entity that failed with a
    /// diagnostic).
    Nothing,
}

/// Reads one directory entry, pushing its diagnostics in the order the sequential reader
/// reported them.
fn read_entry(
    cx: &Context<'_, '_>,
    entry: &Result<DirectoryEntry, ParseError>,
    users: &BTreeMap<usize, Vec<(usize, i64)>>,
    members: &BTreeSet<usize>,
    diags: &mut Vec<Diagnostic>,
) -> Outcome {
    let entry = match entry {
        Ok(e) => e,
        Err(e) => {
            diags.push(parse_diag("iges.entity", e));
            return Outcome::Nothing;
        }
    };
    if members.contains(&entry.pointer) {
        // Read with its 102 (joined into it or emitted as one of its pieces).
        return Outcome::Nothing;
    }
    if let Some(parents) = construction_of(entry, users) {
        diags.push(Diagnostic::info(
            "construction_curve",
            format!(
                "physically dependent on {parents}: read as part of that surface (its axis, generatrix, directrix or rail), not as a curve of its own"
            ),
            entity_location(entry),
        ));
        return Outcome::Nothing;
    }
    let t = entry.entity_type;
    let mut pieces: Vec<(DirectoryEntry, Geometry, Meta)> = Vec::new();
    match t {
        126 => {
            let Some((g, m)) = read_curve(cx, entry, cx.factor, diags) else {
                return Outcome::Nothing;
            };
            pieces.push((entry.clone(), g, m));
        }
        128 => {
            let Some((g, m)) = read_surface(cx, entry, cx.factor, diags) else {
                return Outcome::Nothing;
            };
            pieces.push((entry.clone(), g, m));
        }
        100 | 104 | 106 | 110 | 112 => {
            let Some(c) = curves::simple_curve(cx, entry, diags) else {
                return Outcome::Nothing;
            };
            pieces.push((entry.clone(), Geometry::Curve(c.curve), c.meta));
        }
        102 => {
            match curves::composite(cx, entry, !cx.edge_chains.contains(&entry.pointer), diags) {
                Some(Composite::Joined(c)) => {
                    pieces.push((entry.clone(), Geometry::Curve(c.curve), c.meta));
                }
                Some(Composite::Pieces(list)) => {
                    for (member, mut c) in list {
                        c.meta
                            .used_by
                            .push(compact_str::format_compact!("D{}", entry.pointer));
                        pieces.push((member, Geometry::Curve(c.curve), c.meta));
                    }
                }
                None => return Outcome::Nothing,
            }
        }
        t if SURFACE_TYPES.contains(&t) => {
            let Some(s) = surfaces::surface(cx, entry, diags) else {
                return Outcome::Nothing;
            };
            pieces.push((entry.clone(), Geometry::Surface(s.surface), s.meta));
        }
        124 => return Outcome::Nothing,
        // Read by the topology and subfigure passes, which report what they leave out.
        t if matches!(t, 308 | 408) || super::topology::TOPOLOGY_TYPES.iter().any(|x| x.0 == t) => {
            return Outcome::Nothing;
        }
        // A group of trimmed faces is the shell the topology pass sews them into.
        402 if !cx.options.geometry_only && cx.face_groups.groups.contains(&entry.pointer) => {
            return Outcome::Nothing;
        }
        t => {
            if let Some(why) = inexact(t) {
                diags.push(
                    Diagnostic::warning(
                        "no_exact_form",
                        format!("{t} entity: {why}; not represented"),
                        entity_location(entry),
                    )
                    .not_carried(),
                );
                return Outcome::Nothing;
            }
            // A point or direction physically dependent on its user (IGES 5.3 section
            // 2.2.4.4.9: the location and axes of a 190-198 analytic surface) is carried in
            // that user's geometry.
            if matches!(t, 116 | 123) && entry.status.subordinate & 1 == 1 {
                return Outcome::Nothing;
            }
            return Outcome::Skipped(t);
        }
    }
    let mut out = Vec::with_capacity(pieces.len());
    for (source, geometry, meta) in pieces {
        if let Some(e) = finish(
            cx,
            &source,
            geometry,
            meta,
            users,
            t != 126 && t != 128,
            diags,
        ) {
            out.push(e);
        }
    }
    Outcome::Entities(out)
}

/// The surfaces (120, 122, 118) an entity is the construction curve of, when it is
/// physically dependent (DE status subordinate switch 01 or 03, IGES 5.3 section 2.2.4.4.9.2)
/// and has no other user: such a curve exists only as part of its parent.
fn construction_of(
    entry: &DirectoryEntry,
    users: &BTreeMap<usize, Vec<(usize, i64)>>,
) -> Option<String> {
    if entry.status.subordinate & 1 == 0 {
        return None;
    }
    let list = users.get(&entry.pointer)?;
    list.iter()
        .all(|&(_, ty)| matches!(ty, 118 | 120 | 122))
        .then(|| {
            list.iter()
                .map(|(de, ty)| format!("D{de} ({ty})"))
                .collect::<Vec<_>>()
                .join(", ")
        })
}

/// The entity of a converted curve or surface: the unit factor applied (`scale`: when the
/// conversion did not apply it), parameter-space curves made 2-D, its users listed (and
/// the trims and topology that are not applied reported).
fn finish(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    geometry: Geometry,
    mut meta: Meta,
    users: &BTreeMap<usize, Vec<(usize, i64)>>,
    scale: bool,
    diags: &mut Vec<Diagnostic>,
) -> Option<Entity> {
    let f = cx.factor.filter(|_| scale);
    let m: Option<Affine> = f.map(|f| [[f, 0.0, 0.0, 0.0], [0.0, f, 0.0, 0.0], [0.0, 0.0, f, 0.0]]);
    let scaled = match (geometry, m) {
        (g, None) => Ok(g),
        (Geometry::Curve(c), Some(m)) => c.transform(&m).map(Geometry::Curve),
        (Geometry::Surface(s), Some(m)) => s.transform(&m).map(Geometry::Surface),
    };
    let mut geometry = match scaled {
        Ok(g) => g,
        Err(e) => {
            diags.push(Diagnostic::error(
                "geometry.invalid",
                format!("{e}; entity not loaded"),
                entity_location(entry),
            ));
            return None;
        }
    };
    // Parameter-space curves (use flag 05, or the role of a 142's B(t) / a 508 loop's
    // curve) stay 2-D when every z is 0; 126 decides this itself.
    if let Geometry::Curve(c) = &geometry
        && entry.entity_type != 126
        && c.dimension() == 3
        && (cx.parametric.contains(&entry.pointer) || entry.status.use_flag == 5)
        && c.control_points().iter().all(|p| p[2] == 0.0)
    {
        let (p, k, pts, w, _) = c.clone().into_parts();
        if let Ok(c2) = NurbsCurve::with_dimension(p, k, pts, w, 2) {
            geometry = Geometry::Curve(c2);
        }
    }
    if let Some(list) = users.get(&entry.pointer) {
        let mut trim = Vec::new();
        let mut topo = Vec::new();
        for &(de, ty) in list {
            meta.used_by.push(compact_str::format_compact!("D{de}"));
            // Trimmed faces (144 with 142 boundaries), bounded surfaces (143 with 141
            // boundaries) and B-rep topology are read into the document's topology unless
            // the options ask for geometry only.
            let read_as_topology = !cx.options.geometry_only;
            if matches!(ty, 141..=144) && !read_as_topology {
                trim.push(format!("D{de} ({ty})"));
            } else if matches!(ty, 186 | 502..=514) && !read_as_topology {
                topo.push(format!("D{de} ({ty})"));
            }
        }
        if !trim.is_empty() {
            diags.push(
                Diagnostic::info(
                    "trim_ignored",
                    format!(
                        "used by {}; the trim is not applied, the untrimmed {} is returned",
                        trim.join(", "),
                        if matches!(geometry, Geometry::Curve(_)) {
                            "curve"
                        } else {
                            "surface"
                        }
                    ),
                    entity_location(entry),
                )
                .not_carried(),
            );
        }
        if !topo.is_empty() {
            diags.push(
                Diagnostic::info(
                    "topology_ignored",
                    format!(
                        "used by {}; that topology (B-rep edge, loop or face) is not converted",
                        topo.join(", ")
                    ),
                    entity_location(entry),
                )
                .not_carried(),
            );
        }
    }
    Some(Entity {
        id: compact_str::format_compact!("D{}", entry.pointer),
        geometry,
        source: Source {
            entity: super::entity_type_name(entry.entity_type),
            line: Some(entry.line),
        },
        meta,
    })
}

/// The 102 Composite Curves that bound faces: named by a 142 (C(t) or B(t); IGES 5.3
/// section 4.32), a 141 (its model-space and parameter-space curves; type 141), a 504 edge
/// (section 4.144) or a 508 loop's parameter-space curves (section 4.145).
fn edge_chains(file: &IgesFile<'_>) -> BTreeSet<usize> {
    let mut out = BTreeSet::new();
    let mut add = |p: i64| {
        if let Some(e) = file.entry(p).filter(|e| e.entity_type == 102) {
            out.insert(e.pointer);
        }
    };
    for entry in file.entries.iter().flatten() {
        match entry.entity_type {
            142 => {
                if let Ok(c) = file.decode::<CurveOnSurface142>(entry).record {
                    add(c.model_curve);
                    add(c.parameter_curve);
                }
            }
            141 => {
                if let Ok(b) = file.decode::<Boundary141>(entry).record {
                    for c in &b.curves {
                        add(c.curve);
                        c.parameter_curves.iter().for_each(|&q| add(q));
                    }
                }
            }
            504 => {
                if let Ok(l) = file.decode::<EdgeList504>(entry).record {
                    l.edges.iter().for_each(|e| add(e.curve));
                }
            }
            508 => {
                if let Ok(l) = file.decode::<Loop508>(entry).record {
                    for (_, c) in l.edges.iter().flat_map(|e| &e.parameter_curves) {
                        add(*c);
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// The DE pointers of the constituents of every readable 102 Composite Curve.
fn composite_members(file: &IgesFile<'_>) -> BTreeSet<usize> {
    let mut out = BTreeSet::new();
    for entry in file.entries.iter().flatten() {
        if entry.entity_type != 102 {
            continue;
        }
        if let Ok(c) = file.decode::<CompositeCurve102>(entry).record {
            out.extend(
                c.members
                    .iter()
                    .filter_map(|&m| file.entry(m))
                    .filter(|m| m.entity_type != 102)
                    .map(|m| m.pointer),
            );
        }
    }
    out
}

/// For every surface named by a 144 Trimmed Surface (IGES 5.3 section 4.34), a 143
/// Bounded Surface (type 143) or a 510 Face (section 4.146), the model-space curves that
/// bound those faces: the C(t) of the 142 boundaries (section 4.32), the model-space
/// curves of the 141 boundaries and the 504 edge curves of the 508 loops (sections 4.144,
/// 4.145).
fn boundaries(file: &IgesFile<'_>) -> BTreeMap<usize, Vec<i64>> {
    let mut map: BTreeMap<usize, Vec<i64>> = BTreeMap::new();
    let mut edge_lists: BTreeMap<usize, Option<EdgeList504>> = BTreeMap::new();
    for entry in file.entries.iter().flatten() {
        match entry.entity_type {
            144 => {
                let Ok(t) = file.decode::<TrimmedSurface144>(entry).record else {
                    continue;
                };
                let Some(s) = file.entry(t.surface) else {
                    continue;
                };
                let list = map.entry(s.pointer).or_default();
                for b in std::iter::once(t.outer).chain(t.inner.iter().copied()) {
                    if let Some(c) = file
                        .entry(b)
                        .filter(|e| e.entity_type == 142)
                        .and_then(|e| file.decode::<CurveOnSurface142>(e).record.ok())
                        && c.model_curve != 0
                    {
                        list.push(c.model_curve);
                    }
                }
            }
            143 => {
                let Ok(b) = file.decode::<BoundedSurface143>(entry).record else {
                    continue;
                };
                let Some(s) = file.entry(b.surface) else {
                    continue;
                };
                let list = map.entry(s.pointer).or_default();
                for e in b.boundaries.iter().filter_map(|&p| file.entry(p)) {
                    if let Some(r) = (e.entity_type == 141)
                        .then(|| file.decode::<Boundary141>(e).record.ok())
                        .flatten()
                    {
                        list.extend(r.curves.iter().map(|c| c.curve));
                    }
                }
            }
            510 => {
                let Ok(f) = file.decode::<Face510>(entry).record else {
                    continue;
                };
                let Some(s) = file.entry(f.surface) else {
                    continue;
                };
                let surface = s.pointer;
                for l in f.loops.iter().filter_map(|&l| file.entry(l)) {
                    let Ok(lp) = file.decode::<Loop508>(l).record else {
                        continue;
                    };
                    for e in lp.edges.iter().filter(|e| e.kind == 0) {
                        let Some(list_entry) = file.entry(e.edge) else {
                            continue;
                        };
                        let list = edge_lists
                            .entry(list_entry.pointer)
                            .or_insert_with(|| file.decode::<EdgeList504>(list_entry).record.ok());
                        let curve = list.as_ref().and_then(|l| {
                            usize::try_from(e.index - 1)
                                .ok()
                                .and_then(|i| l.edges.get(i))
                                .map(|edge| edge.curve)
                        });
                        if let Some(c) = curve {
                            map.entry(surface).or_default().push(c);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    // A curve bounding several faces of one surface is projected once.
    for list in map.values_mut() {
        list.sort_unstable();
        list.dedup();
    }
    map
}

/// The unit of the file (flag wins over name); a model-space scale other than 1 is reported.
fn units(file: &IgesFile<'_>, diags: &mut Vec<Diagnostic>) -> LengthUnit {
    let g = &file.global;
    let by_name = g.units_name.as_deref().and_then(LengthUnit::parse_name);
    let unit = match g.units_flag {
        Some(3) | Some(0) | None => match by_name {
            Some(u) => u,
            None => {
                let (code, msg) = if g.units_flag.is_none() && g.units_name.is_none() {
                    (
                        "unit_default",
                        "no units flag or name: the IGES default, inch (flag 1), is assumed"
                            .to_owned(),
                    )
                } else {
                    (
                        "unit_unknown",
                        format!(
                            "units flag {:?} refers to the unit name {:?}, which is not known: inch assumed",
                            g.units_flag, g.units_name
                        ),
                    )
                };
                diags.push(Diagnostic::warning(code, msg, global_location()));
                LengthUnit::In
            }
        },
        Some(flag) => match LengthUnit::from_iges_flag(flag) {
            Some(u) => {
                if let Some(n) = by_name
                    && n != u
                {
                    diags.push(Diagnostic::warning(
                        "unit_conflict",
                        format!(
                            "units flag {flag} ({}) and units name {:?} disagree; the flag wins",
                            u.iges_name(),
                            g.units_name.as_deref().unwrap_or("")
                        ),
                        global_location(),
                    ));
                }
                u
            }
            None => {
                let u = by_name.unwrap_or(LengthUnit::In);
                diags.push(Diagnostic::warning(
                    "unit_unknown",
                    format!(
                        "units flag {flag} is not defined by IGES 5.3; {} assumed",
                        u.iges_name()
                    ),
                    global_location(),
                ));
                u
            }
        },
    };
    let scale = g.model_scale.unwrap_or(1.0);
    if scale != 1.0 {
        diags.push(Diagnostic::warning(
            "model_scale_ignored",
            format!(
                "model space scale (Global parameter 13) is {scale}; coordinates are kept as model-space values (as Open CASCADE does)"
            ),
            global_location(),
        ));
    }
    unit
}

/// For every curve and surface, the entities that reference it: trims (141-144), composite
/// curves (102), the surfaces built from curves (108, 118, 120, 122) and B-rep elements
/// (504, 510): `(user DE, user type)`, by the DE pointers their declarations name.
fn users(file: &IgesFile<'_>) -> BTreeMap<usize, Vec<(usize, i64)>> {
    let mut map: BTreeMap<usize, Vec<(usize, i64)>> = BTreeMap::new();
    for entry in file.entries.iter().flatten() {
        let ty = entry.entity_type;
        if !matches!(ty, 102 | 108 | 118 | 120 | 122 | 141..=144 | 504 | 510) {
            continue;
        }
        let Some(Ok(references)) = file.references(entry) else {
            continue; // an unreadable user is reported nowhere else; its users are unknown
        };
        for (_, pointer, _) in references {
            if let Some(target) = file.entry(pointer)
                && (CURVE_TYPES.contains(&target.entity_type)
                    || SURFACE_TYPES.contains(&target.entity_type))
            {
                map.entry(target.pointer)
                    .or_default()
                    .push((entry.pointer, ty));
            }
        }
    }
    map
}

/// The DE pointers of the curves that live in a surface's parameter space: the B(t) curve
/// of a 142 Curve on a Parametric Surface (IGES 5.3 section 4.32), directly or as members
/// of a 102 Composite Curve, those of a 141 Boundary (type 141), and the parameter-space
/// curves of a 508 Loop (section 4.145).
fn parameter_space_curves(file: &IgesFile<'_>) -> BTreeSet<usize> {
    let mut out = BTreeSet::new();
    let add = |ptr: i64, out: &mut BTreeSet<usize>| {
        let Some(target) = file.entry(ptr) else {
            return;
        };
        match target.entity_type {
            102 => {
                out.insert(target.pointer);
                let Ok(composite) = file.decode::<CompositeCurve102>(target).record else {
                    return;
                };
                for member in composite.members {
                    if let Some(m) = file.entry(member)
                        && CURVE_TYPES.contains(&m.entity_type)
                    {
                        out.insert(m.pointer);
                    }
                }
            }
            t if CURVE_TYPES.contains(&t) => {
                out.insert(target.pointer);
            }
            _ => {}
        }
    };
    for entry in file.entries.iter().flatten() {
        match entry.entity_type {
            142 => {
                if let Ok(c) = file.decode::<CurveOnSurface142>(entry).record {
                    add(c.parameter_curve, &mut out);
                }
            }
            141 => {
                if let Ok(b) = file.decode::<Boundary141>(entry).record {
                    for c in &b.curves {
                        c.parameter_curves.iter().for_each(|&q| add(q, &mut out));
                    }
                }
            }
            508 => {
                if let Ok(l) = file.decode::<Loop508>(entry).record {
                    for (_, curve) in l.edges.iter().flat_map(|e| &e.parameter_curves) {
                        add(*curve, &mut out);
                    }
                }
            }
            _ => {}
        }
    }
    out
}

fn global_location() -> Location {
    Location {
        section: Some('G'),
        sequence: Some(1),
        ..Location::default()
    }
}

/// The location of an entity: its first DE line.
pub(super) fn entity_location(e: &DirectoryEntry) -> Location {
    Location {
        line: Some(e.line),
        column: None,
        entity: Some(format!("D{}", e.pointer)),
        section: Some('D'),
        sequence: Some(e.pointer),
    }
}

fn parse_diag(code: &str, e: &ParseError) -> Diagnostic {
    Diagnostic::error(
        limit_code(e).unwrap_or(code),
        e.kind.to_string(),
        Location {
            line: e.line,
            column: e.column,
            entity: e.de.map(|d| format!("D{d}")),
            section: (e.section != ' ').then_some(e.section),
            sequence: (e.sequence != 0).then_some(e.sequence),
        },
    )
}

/// The `limit.*` code of a parser limit error (the same codes the STEP reader uses), so a
/// caller can tell "too big for this configuration" from "malformed". The parser's
/// `ErrorKind::Limit` carries only a message; the parameter-count limit is the only one
/// whose message mentions parameters, the others count entries/records.
fn limit_code(e: &ParseError) -> Option<&'static str> {
    match &e.kind {
        iges::ErrorKind::Limit(m) if m.contains("parameter") => Some("limit.params_per_entity"),
        iges::ErrorKind::Limit(m) if m.contains("bytes") => Some("limit.input_bytes"),
        iges::ErrorKind::Limit(_) => Some("limit.entities"),
        _ => None,
    }
}

/// What the parser tolerated. Each is a violation of IGES 5.3 (80-column records and
/// consecutive sequence numbers, section 2.1; Terminate counts, section 2.2.4.6; DE field
/// 14, section 2.2.4.4; the Global section, section 2.2.4.3) read with its one meaning:
/// non-conforming, an error for `validate`. CR LF line ends are not: the standard fixes the
/// 80 columns of a record, not the line terminator outside them (section 2.1), so a file
/// whose every line is 80 columns plus CR LF conforms; that is an informational note.
fn warning_diag(w: &ParseWarning) -> Diagnostic {
    let location = Location {
        line: w.line,
        column: None,
        entity: w.de.map(|d| format!("D{d}")),
        section: (w.section != ' ').then_some(w.section),
        sequence: (w.sequence != 0).then_some(w.sequence),
    };
    if w.code == "crlf" {
        Diagnostic::info(w.code, w.message.clone(), location)
    } else {
        Diagnostic::nonconforming(w.code, w.message.clone(), location)
    }
}

/// The 124 chain of an entity, or an error diagnostic.
fn transforms(
    file: &IgesFile<'_>,
    entry: &DirectoryEntry,
    options: &ImportOptions,
    meta: &mut Meta,
    diags: &mut Vec<Diagnostic>,
) -> Option<Vec<Transform124>> {
    match chain::resolve(file, entry.transform, options.limits.max_nesting_depth) {
        Ok(list) => {
            meta.transforms_applied = list
                .iter()
                .map(|(de, _)| compact_str::format_compact!("D{de}"))
                .collect();
            Some(list.into_iter().map(|(_, t)| t).collect())
        }
        Err(e) => {
            let mut loc = entity_location(entry);
            if let ChainError::Parse(pe) = &e {
                loc = parse_diag("", pe).location;
            }
            diags.push(Diagnostic::error(
                "transform.invalid",
                format!("{e}; entity not loaded"),
                loc,
            ));
            None
        }
    }
}

fn apply_all(ts: &[Transform124], p: Point3, factor: Option<f64>) -> Point3 {
    let mut q = p;
    for t in ts {
        q = t.apply(q);
    }
    if let Some(f) = factor {
        q = [q[0] * f, q[1] * f, q[2] * f];
    }
    q
}

/// The precision of a 126/128 form check ([`forms::labelled_shape`]), computed when the
/// check needs it: four times [`analysis::written_point_rounding`] of the poles and weights
/// as the file wrote them, times [`stretch`].
fn written_precision<'a>(
    ts: &'a [Transform124],
    factor: Option<f64>,
    points: &'a [Point3],
    weights: Option<&'a [f64]>,
) -> impl FnOnce() -> f64 + 'a {
    move || {
        4.0 * stretch(ts, factor)
            * analysis::written_point_rounding(points, weights.unwrap_or_default())
    }
}

/// A bound on how much [`apply_all`] stretches a length: per 124 of the chain 1 for a
/// rotation or reflection (the linear part's columns orthonormal within 1e-12; IGES 5.3
/// section 4.21 forms 0 and 1), else its Frobenius norm (at least its largest singular
/// value); times the unit factor.
fn stretch(ts: &[Transform124], factor: Option<f64>) -> f64 {
    let of = |t: &Transform124| {
        let c = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| t.apply_linear(e));
        let orthonormal = (0..3).all(|i| {
            (0..3).all(|j| {
                let d = dot(c[i], c[j]) - if i == j { 1.0 } else { 0.0 };
                d.abs() <= 1e-12
            })
        });
        if orthonormal {
            1.0
        } else {
            c.iter().map(|v| dot(*v, *v)).sum::<f64>().sqrt()
        }
    };
    ts.iter().map(of).product::<f64>() * factor.map_or(1.0, f64::abs)
}

fn check_limits(
    entry: &DirectoryEntry,
    degrees: &[usize],
    poles: usize,
    options: &ImportOptions,
    diags: &mut Vec<Diagnostic>,
) -> bool {
    if let Some(&d) = degrees.iter().find(|&&d| d > options.limits.max_degree) {
        diags.push(Diagnostic::error(
            "limit.degree",
            format!(
                "degree {d} is above the limit of {}; entity not loaded",
                options.limits.max_degree
            ),
            entity_location(entry),
        ));
        return false;
    }
    if poles > options.limits.max_poles {
        diags.push(Diagnostic::error(
            "limit.poles",
            format!(
                "{poles} control points are above the limit of {}; entity not loaded",
                options.limits.max_poles
            ),
            entity_location(entry),
        ));
        return false;
    }
    true
}

fn flag(value: i64, name: &str, entry: &DirectoryEntry, diags: &mut Vec<Diagnostic>) -> bool {
    if value != 0 && value != 1 {
        // IGES 5.3 sections 4.23/4.24: PROP1-5 are 0 or 1.
        diags.push(Diagnostic::nonconforming(
            "flag_invalid",
            format!(
                "{name} = {value}; IGES allows 0 or 1 (read as {})",
                value != 0
            ),
            entity_location(entry),
        ));
    }
    value != 0
}

/// PROP3 against the weights: returns the weights to keep (`None` = polynomial).
fn weights_policy(
    prop3: bool,
    weights: Vec<f64>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Vec<f64>> {
    let first = weights.first().copied().unwrap_or(1.0);
    let equal = weights.iter().all(|&w| w == first);
    match (prop3, equal) {
        (true, true) => None,
        (true, false) if weights.iter().any(|&w| !(w.is_finite() && w > 0.0)) => {
            // Unusable weights on an entity flagged polynomial: read it as polynomial, as
            // Open CASCADE does (it never looks at the weights when PROP3 = 1).
            diags.push(Diagnostic::warning(
                "prop3_inconsistent",
                "PROP3 = 1 (polynomial) and the weights differ, some not positive; the weights are ignored (polynomial)".to_owned(),
                entity_location(entry),
            ));
            None
        }
        (true, false) => {
            diags.push(Diagnostic::warning(
                "prop3_inconsistent",
                "PROP3 = 1 (polynomial) but the weights differ; the weights are kept (rational). Open CASCADE would drop them".to_owned(),
                entity_location(entry),
            ));
            Some(weights)
        }
        (false, true) => {
            diags.push(Diagnostic::info(
                "prop3_rational_equal_weights",
                format!("PROP3 = 0 (rational) with all weights equal to {first}; kept rational (the same geometry as polynomial)"),
                entity_location(entry),
            ));
            Some(weights)
        }
        (false, false) => Some(weights),
    }
}

pub(super) fn name_of(entry: &DirectoryEntry) -> Option<String> {
    (!entry.label.is_empty()).then(|| entry.label.clone())
}

/// The `nu x nv` grid (u-major) of `f` applied to IGES 128 data listed first index
/// fastest (`src[j * nu + i]` is cell `(i, j)`), by strided reads: the same cells as
/// `Grid::from_fn(nu, nv, |i, j| f(src[j * nu + i]))` without per-cell index arithmetic and
/// bounds checks. `None` when `src` does not hold `nu * nv` values.
fn transposed<T: Copy, U>(src: &[T], nu: usize, nv: usize, f: impl Fn(T) -> U) -> Option<Grid<U>> {
    if nu.checked_mul(nv) != Some(src.len()) {
        return None;
    }
    let mut data = Vec::with_capacity(src.len());
    if nu > 0 {
        for i in 0..nu {
            data.extend(src.iter().skip(i).step_by(nu).map(|&x| f(x)));
        }
    }
    Grid::from_u_major(nu, nv, data)
}

/// Weights of an IGES 128 (first index fastest) as a u-major grid; only reached when the
/// count does not match, which the record's layout rules out.
fn from_file_order(w: &[f64], nu: usize, nv: usize) -> Grid<f64> {
    Grid::from_fn(nu, nv, |i, j| {
        w.get(j * nu + i).copied().unwrap_or(f64::NAN)
    })
}

/// Passes the decoded entity's warnings on and returns its record; a failure becomes an
/// `iges.entity` error diagnostic and `None`, so the other entities still load.
pub(super) fn decoded<T>(d: iges::Decoded<T>, diags: &mut Vec<Diagnostic>) -> Option<T> {
    diags.extend(d.warnings.iter().map(warning_diag));
    d.record
        .map_err(|e| diags.push(parse_diag("iges.entity", &e)))
        .ok()
}

/// A 126 (IGES 5.3 section 4.23) with its flags checked, its 124 chain and the unit
/// `factor` applied, trimmed to `V(0)..V(1)` when the options ask.
pub(super) fn read_curve(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    factor: Option<f64>,
    diags: &mut Vec<Diagnostic>,
) -> Option<(Geometry, Meta)> {
    let (file, options) = (cx.file, cx.options);
    let parametric = cx.parametric.contains(&entry.pointer);
    let rec = decoded(file.decode::<Curve126>(entry), diags)?;
    if !check_limits(entry, &[rec.degree], rec.points.len(), options, diags) {
        return None;
    }
    let loc = entity_location(entry);
    if rec.v0.is_none() && full_with_one_pole_less(&rec) {
        diags.push(Diagnostic::error(
            "iges.entity",
            format!(
                "the record ends after its control points (no V(0), V(1)), and its {} parameters \
                 also read as a complete 126 with K = {}: K does not decide between the two; \
                 entity not loaded",
                5 * rec.points.len() + rec.degree + 7,
                rec.points.len().saturating_sub(2)
            ),
            loc,
        ));
        return None;
    }
    let mut meta = Meta {
        name: name_of(entry),
        form: Some(super::form_text(entry.form)),
        ..Meta::default()
    };
    let planar = flag(rec.planar, "PROP1 (planar)", entry, diags);
    let closed = flag(rec.closed, "PROP2 (closed)", entry, diags);
    let polynomial = flag(rec.polynomial, "PROP3 (polynomial)", entry, diags);
    let periodic = flag(rec.periodic, "PROP4 (periodic)", entry, diags);
    meta.closed_u = Some(closed);
    meta.periodic_u = Some(periodic);
    let ts = transforms(file, entry, options, &mut meta, diags)?;
    let points: Vec<Point3> = rec
        .points
        .iter()
        .map(|&p| apply_all(&ts, p, factor))
        .collect();
    // The weights as written, for the precision of a form check (`forms::labelled_shape`).
    let written_weights = (entry.form != 0).then(|| rec.weights.clone());
    let weights = weights_policy(polynomial, rec.weights, entry, diags);
    // IGES 2-D parametric curves stay 2-D: use flag 05, or the role of a parameter-space
    // curve (the B(t) of a 142, a 508 loop pcurve) whatever the flag says (Open CASCADE
    // does not always set 05).
    let dimension =
        if (parametric || entry.status.use_flag == 5) && points.iter().all(|p| p[2] == 0.0) {
            2
        } else {
            3
        };
    let curve = match NurbsCurve::with_dimension(rec.degree, rec.knots, points, weights, dimension)
    {
        Ok(c) => c,
        Err(e) => {
            diags.push(Diagnostic::error(
                "geometry.invalid",
                format!("126 entity is not a valid B-spline: {e}; entity not loaded"),
                loc,
            ));
            return None;
        }
    };
    let tol = analysis::tolerance(curve.control_points().iter())
        .max(file.global.resolution.unwrap_or(0.0));
    // PROP2 vs the end points; PROP4 vs the knot layout (never used to rewrite knots).
    let geo_closed = analysis::curve_closed(&curve, tol);
    if closed != geo_closed {
        diags.push(Diagnostic::warning(
            "flag_mismatch",
            format!(
                "PROP2 (closed) = {} but the curve's ends are {}",
                rec.closed,
                if geo_closed { "equal" } else { "apart" }
            ),
            loc.clone(),
        ));
    }
    if periodic && !analysis::curve_periodic(&curve, tol) {
        let how = if analysis::clamped(curve.knots(), curve.degree()) {
            "the knots are clamped (as Open CASCADE writes periodic curves)"
        } else {
            "the knots and poles do not have the periodic layout"
        };
        diags.push(Diagnostic::warning(
            "flag_mismatch",
            format!("PROP4 (periodic) = 1 but {how}; the data is read as written"),
            loc.clone(),
        ));
    }
    // V(0), V(1): kept; checked against the knot domain.
    let (d0, d1) = curve.domain();
    match (rec.v0, rec.v1) {
        (Some(a), Some(b)) => {
            meta.parameter_range = Some(Box::new(ParameterRange { u: (a, b), v: None }));
            if !(a >= d0 && b <= d1 && a < b) {
                diags.push(Diagnostic::warning(
                    "param_range_outside",
                    format!("V(0), V(1) = {a}, {b} is not an increasing range inside the knot domain [{d0}, {d1}]"),
                    loc.clone(),
                ));
            }
        }
        _ => diags.push(Diagnostic::nonconforming(
            "missing_param_range",
            format!("V(0)/V(1) absent (IGES 5.3 section 4.23 requires them): the knot domain [{d0}, {d1}] is used"),
            loc.clone(),
        )),
    }
    // The plane normal of a planar curve, rotated with the poles.
    if planar {
        match rec.normal {
            Some(n) if n != [0.0, 0.0, 0.0] => {
                let mut m = n;
                for t in &ts {
                    m = t.apply_linear(m);
                }
                // In the file's own numbers (planarity does not depend on the placement),
                // within what their written digits carry.
                let written = analysis::plane_tolerance(&rec.points, n)
                    .max(file.global.resolution.unwrap_or(0.0));
                if !analysis::on_plane(&rec.points, n, written) {
                    diags.push(Diagnostic::warning(
                        "flag_mismatch",
                        "PROP1 (planar) = 1 but the control points do not lie in the plane of the given normal (beyond the precision of the digits written)".to_owned(),
                        loc.clone(),
                    ));
                }
                meta.plane_normal = Some(Box::new(m));
            }
            // IGES 5.3 section 4.23: a planar curve carries its unit normal.
            _ => diags.push(Diagnostic::nonconforming(
                "missing_normal",
                "PROP1 (planar) = 1 but the plane normal is absent or zero".to_owned(),
                loc.clone(),
            )),
        }
    }
    let curve = if options.trim_to_parameter_range {
        let range = match (rec.v0, rec.v1) {
            (Some(a), Some(b)) if a >= d0 && b <= d1 && a < b => Some((a, b)),
            _ => None,
        };
        let trimmed = range.map(|(a, b)| curve.piece(a, b));
        match trimmed {
            Some(Ok(c)) => {
                if c.domain() != (d0, d1) {
                    diags.push(trimmed_diag(&loc, "V(0)..V(1)", c.domain(), None));
                }
                c
            }
            Some(Err(e)) => {
                diags.push(Diagnostic::error(
                    "geometry.invalid",
                    format!("trimming to V(0)..V(1) failed: {e}; entity not loaded"),
                    loc,
                ));
                return None;
            }
            None => {
                diags.push(not_trimmed(&loc, (d0, d1), None));
                curve
            }
        }
    } else {
        curve
    };
    let geometry = Geometry::Curve(curve);
    let written = written_precision(&ts, factor, &rec.points, written_weights.as_deref());
    (meta.shape, meta.shape_tolerance) =
        forms::labelled_shape(126, entry.form, &geometry, &loc, diags, written);
    Some((geometry, meta))
}

/// Whether a 126 that ends after its control points (`17 + 5K + M - 5` parameters) is also
/// a complete record with `K - 1`: the same parameters read as `K + M + 1` knots, `K`
/// weights, `K` points, V(0), V(1) and the normal (IGES 5.3 section 4.23). A raised K turns
/// a complete record into exactly such a short one, so when the shorter reading is a valid
/// curve with its range inside its knots, the record has two meanings and is not read.
fn full_with_one_pole_less(rec: &Curve126) -> bool {
    let m = rec.degree;
    let Some(k) = rec.points.len().checked_sub(2) else {
        return false;
    };
    if k < m || m == 0 {
        return false;
    }
    let flat: Vec<f64> = rec
        .knots
        .iter()
        .chain(&rec.weights)
        .copied()
        .chain(rec.points.iter().flatten().copied())
        .collect();
    let (nk, n) = (k + m + 2, k + 1);
    let (Some(knots), Some(weights), Some(&[v0, v1])) = (
        flat.get(..nk),
        flat.get(nk..nk + n),
        flat.get(nk + 4 * n..nk + 4 * n + 2),
    ) else {
        return false;
    };
    knots.windows(2).all(|w| w[0] <= w[1])
        && weights.iter().all(|&w| w > 0.0)
        && knots[m] <= v0
        && v0 < v1
        && v1 <= knots[k + 1]
}

fn trimmed_diag(loc: &Location, what: &str, u: (f64, f64), v: Option<(f64, f64)>) -> Diagnostic {
    let v = v.map_or(String::new(), |(c, d)| format!(" x [{c}, {d}]"));
    Diagnostic::info(
        "trimmed_to_range",
        format!(
            "trimmed exactly to the declared {what}: [{}, {}]{v} (knot insertion, NURBS Book A5.1)",
            u.0, u.1
        ),
        loc.clone(),
    )
}

fn not_trimmed(loc: &Location, u: (f64, f64), v: Option<(f64, f64)>) -> Diagnostic {
    let v = v.map_or(String::new(), |(c, d)| format!(" x [{c}, {d}]"));
    Diagnostic::warning(
        "trim_not_applied",
        format!(
            "trimming to the declared parameter range was asked, but the entity declares no increasing range inside its knot domain; the whole domain [{}, {}]{v} is kept",
            u.0, u.1
        ),
        loc.clone(),
    )
}

/// A 128 (IGES 5.3 section 4.24) with its flags checked, its 124 chain and the unit
/// `factor` applied, trimmed to `U(0)..U(1) x V(0)..V(1)` when the options ask.
fn read_surface(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    factor: Option<f64>,
    diags: &mut Vec<Diagnostic>,
) -> Option<(Geometry, Meta)> {
    let (file, options) = (cx.file, cx.options);
    let rec = decoded(file.decode::<Surface128>(entry), diags)?;
    if !check_limits(entry, &rec.degree, rec.points.len(), options, diags) {
        return None;
    }
    let loc = entity_location(entry);
    let mut meta = Meta {
        name: name_of(entry),
        form: Some(super::form_text(entry.form)),
        ..Meta::default()
    };
    let closed = [
        flag(rec.closed[0], "PROP1 (closed in u)", entry, diags),
        flag(rec.closed[1], "PROP2 (closed in v)", entry, diags),
    ];
    let polynomial = flag(rec.polynomial, "PROP3 (polynomial)", entry, diags);
    let periodic = [
        flag(rec.periodic[0], "PROP4 (periodic in u)", entry, diags),
        flag(rec.periodic[1], "PROP5 (periodic in v)", entry, diags),
    ];
    meta.closed_u = Some(closed[0]);
    meta.closed_v = Some(closed[1]);
    meta.periodic_u = Some(periodic[0]);
    meta.periodic_v = Some(periodic[1]);
    let ts = transforms(file, entry, options, &mut meta, diags)?;
    let [nu, nv] = rec.poles;
    // IGES lists the first (u) index fastest; Grid is u-major: transpose explicitly.
    let points =
        transposed(&rec.points, nu, nv, |p| apply_all(&ts, p, factor)).unwrap_or_else(|| {
            Grid::from_fn(nu, nv, |i, j| {
                let p = rec.points.get(rec.index(i, j)).copied();
                apply_all(&ts, p.unwrap_or([f64::NAN; 3]), factor)
            })
        });
    // The weights as written, for the precision of a form check (`forms::labelled_shape`).
    let written_weights = (entry.form != 0).then(|| rec.weights.clone());
    let weights = weights_policy(polynomial, rec.weights, entry, diags)
        .map(|w| transposed(&w, nu, nv, |x| x).unwrap_or_else(|| from_file_order(&w, nu, nv)));
    let surface = match NurbsSurface::new(
        rec.degree[0],
        rec.degree[1],
        rec.knots_u,
        rec.knots_v,
        points,
        weights,
    ) {
        Ok(s) => s,
        Err(e) => {
            diags.push(Diagnostic::error(
                "geometry.invalid",
                format!("128 entity is not a valid B-spline surface: {e}; entity not loaded"),
                loc,
            ));
            return None;
        }
    };
    let tol = analysis::tolerance(surface.control_points().as_slice().iter())
        .max(file.global.resolution.unwrap_or(0.0));
    for (dir, name) in [(0, "u"), (1, "v")] {
        let geo_closed = analysis::surface_closed(&surface, dir, tol);
        if closed[dir] != geo_closed {
            diags.push(Diagnostic::warning(
                "flag_mismatch",
                format!(
                    "PROP{} (closed in {name}) = {} but the surface's {name} boundaries {}",
                    dir + 1,
                    rec.closed[dir],
                    if geo_closed { "coincide" } else { "are apart" }
                ),
                loc.clone(),
            ));
        }
        if periodic[dir] && !analysis::surface_periodic(&surface, dir, tol) {
            diags.push(Diagnostic::warning(
                "flag_mismatch",
                format!(
                    "PROP{} (periodic in {name}) = 1 but the data does not have the periodic layout; read as written",
                    dir + 4
                ),
                loc.clone(),
            ));
        }
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    match rec.range {
        Some([a, b, c, d]) => {
            meta.parameter_range = Some(Box::new(ParameterRange {
                u: (a, b),
                v: Some((c, d)),
            }));
            if !(a >= u0 && b <= u1 && a < b && c >= v0 && d <= v1 && c < d) {
                diags.push(Diagnostic::warning(
                    "param_range_outside",
                    format!(
                        "U(0), U(1), V(0), V(1) = {a}, {b}, {c}, {d} is not inside the knot domain [{u0}, {u1}] x [{v0}, {v1}]"
                    ),
                    loc.clone(),
                ));
            }
        }
        None => diags.push(Diagnostic::nonconforming(
            "missing_param_range",
            format!("U(0)..V(1) absent (IGES 5.3 section 4.24 requires them): the knot domain [{u0}, {u1}] x [{v0}, {v1}] is used"),
            loc.clone(),
        )),
    }
    let surface = if options.trim_to_parameter_range {
        let range = match rec.range {
            Some([a, b, c, d]) if a >= u0 && b <= u1 && a < b && c >= v0 && d <= v1 && c < d => {
                Some(((a, b), (c, d)))
            }
            _ => None,
        };
        match range.map(|(u, v)| surface.piece(u, v)) {
            Some(Ok(s)) => {
                let (u, v) = s.domain();
                if (u, v) != ((u0, u1), (v0, v1)) {
                    diags.push(trimmed_diag(&loc, "U(0)..U(1) x V(0)..V(1)", u, Some(v)));
                }
                s
            }
            Some(Err(e)) => {
                diags.push(Diagnostic::error(
                    "geometry.invalid",
                    format!("trimming to U(0)..V(1) failed: {e}; entity not loaded"),
                    loc,
                ));
                return None;
            }
            None => {
                diags.push(not_trimmed(&loc, (u0, u1), Some((v0, v1))));
                surface
            }
        }
    } else {
        surface
    };
    let geometry = Geometry::Surface(surface);
    let written = written_precision(&ts, factor, &rec.points, written_weights.as_deref());
    (meta.shape, meta.shape_tolerance) =
        forms::labelled_shape(128, entry.form, &geometry, &loc, diags, written);
    Some((geometry, meta))
}
