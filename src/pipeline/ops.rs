//! The pipeline's operations: convert, info, validate, evaluate, geometric operations and
//! tessellation. Each takes loaded input and returns a report or new bytes.

use crate::exchange::{
    self, Diagnostic, Document, Entity, ExportOptions, Format, LengthUnit, Location,
};
use crate::nurbs::{Geometry, Point3, bounding_box_diagonal, distance};

use super::reports::{
    ConvertReport, EntityDeviation, EntityInfo, EvalReport, EvalResult, FaceInfo, InfoReport,
    PartDeviation, ShellInfo, SolidInfo, StructureInfo, UnitsInfo, ValidationReport,
};
use super::{ErrorKind, InputKind, Loaded, PipelineError, Settings, load};

/// Characters one `f64` takes at most in a reply (`-2.2250738585072014e-308` and a
/// separator): reply estimates count every number at this width, so they bound the text.
const NUMBER_BYTES: f64 = 25.0;

/// Refuses work whose reply would exceed [`Settings::max_reply_bytes`]: `estimate` is the
/// reply size worked out before the work, `what` names the reply, `advice` says how to
/// shrink it.
pub(super) fn check_reply(
    estimate: f64,
    what: &str,
    advice: &str,
    settings: &Settings,
) -> Result<(), PipelineError> {
    if estimate > settings.max_reply_bytes as f64 {
        return Err(PipelineError::new(
            ErrorKind::Limit,
            "limit.reply_bytes",
            format!(
                "the {what} would take about {:.0} bytes, above the reply limit of {} bytes; {advice}",
                estimate, settings.max_reply_bytes
            ),
            Location::default(),
        ));
    }
    Ok(())
}

/// An upper estimate of a written file (STEP, IGES or model JSON): per control point one
/// point record (up to 4 numbers and about 30 bytes of syntax), per knot one number, and
/// 256 bytes of entity records per entity. With `elevation` (`by`, direction, entity), the
/// file the document gives after that degree elevation.
fn estimated_file_bytes(
    doc: &Document,
    elevation: Option<(usize, Direction, Option<&str>)>,
) -> f64 {
    // Degree elevation by t (NURBS Book A5.9): each of the s Bezier segments of a direction
    // gains t control points, and each of its s + 1 distinct knots t more multiplicity.
    let elevated = |n: usize, knots: &[f64], p: usize, by: usize| -> (usize, usize) {
        let segments = knots
            .get(p..knots.len().saturating_sub(p))
            .map_or(0, |d| d.windows(2).filter(|w| w[1] > w[0]).count());
        (
            n.saturating_add(by.saturating_mul(segments)),
            knots.len().saturating_add(by.saturating_mul(segments + 1)),
        )
    };
    doc.entities
        .iter()
        .map(|e| {
            let by = elevation
                .filter(|(_, _, id)| id.is_none_or(|id| is_entity(e, id)))
                .map(|(by, direction, _)| (by, direction));
            let (u, v) = match by.map(|(_, d)| d) {
                Some(Direction::Both) => (true, true),
                Some(Direction::U) => (true, false),
                Some(Direction::V) => (false, true),
                None => (false, false),
            };
            let by = by.map_or(0, |(by, _)| by);
            let (poles, knots) = match &e.geometry {
                Geometry::Curve(c) if u => elevated(c.num_poles(), c.knots(), c.degree(), by),
                Geometry::Curve(c) => (c.num_poles(), c.knots().len()),
                Geometry::Surface(s) => {
                    let (nu, nv) = (s.control_points().nu(), s.control_points().nv());
                    let (nu, ku) = if u {
                        elevated(nu, s.knots_u(), s.degree_u(), by)
                    } else {
                        (nu, s.knots_u().len())
                    };
                    let (nv, kv) = if v {
                        elevated(nv, s.knots_v(), s.degree_v(), by)
                    } else {
                        (nv, s.knots_v().len())
                    };
                    (nu.saturating_mul(nv), ku + kv)
                }
            };
            256.0 + poles as f64 * (4.0 * NUMBER_BYTES + 30.0) + knots as f64 * NUMBER_BYTES
        })
        .sum()
}

/// Whether `id` names the entity: its id, or its id without the `#` (STEP) or `D` (IGES).
fn is_entity(e: &Entity, id: &str) -> bool {
    e.id == id || e.id.trim_start_matches(['#', 'D']) == id
}

/// Checks the estimate of a file (or model JSON) about to be written against
/// [`Settings::max_reply_bytes`] (413 `limit.reply_bytes`).
pub fn check_file_reply(doc: &Document, settings: &Settings) -> Result<(), PipelineError> {
    check_reply(
        estimated_file_bytes(doc, None),
        "written file",
        "send fewer or smaller entities",
        settings,
    )
}

/// What to do with knot-vector ends while converting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClampPolicy {
    /// Keep the knots exactly as read (the default: unclamped and periodic data stays exact).
    #[default]
    Keep,
    /// Clamp every entity (knot insertion at the domain ends; geometry unchanged).
    Clamp,
    /// Unclamp every entity (NURBS Book A12.1; geometry unchanged).
    Unclamp,
}

/// A conversion request.
#[derive(Debug, Clone, Default)]
pub struct ConvertRequest {
    /// Output format.
    pub to: Option<Format>,
    /// Writer options (schema, output unit, time stamp, ...).
    pub export: ExportOptions,
    /// Knot-end policy.
    pub clamp: ClampPolicy,
    /// Re-read the output and compare each entity by sampling; fail when the relative
    /// deviation exceeds this tolerance.
    pub verify: Option<f64>,
}

/// The result of a conversion.
#[derive(Debug, Clone)]
pub struct ConvertOutput {
    /// The format written.
    pub format: Format,
    /// The file text.
    pub text: String,
    /// What happened.
    pub report: ConvertReport,
}

/// A parametric direction of a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Direction {
    /// Along u.
    U,
    /// Along v.
    V,
    /// Both (for curves: the only direction).
    #[default]
    Both,
}

/// A geometric operation on the entities of a document: shape-preserving (elevation,
/// insertion, refinement, clamping, splitting ...), tolerance-bounded (reduction, knot
/// removal), or making new geometry from the old (iso-curves, derivative curves).
#[derive(Debug, Clone, PartialEq)]
pub enum Operation {
    /// Degree elevation by `by` (NURBS Book A5.9/A5.10).
    Elevate {
        /// Amount.
        by: usize,
        /// Surface direction(s).
        direction: Direction,
    },
    /// Clamp both ends (all directions for surfaces).
    Clamp {
        /// Surface direction(s).
        direction: Direction,
    },
    /// Unclamp both ends (A12.1).
    Unclamp {
        /// Surface direction(s).
        direction: Direction,
    },
    /// Insert the knot `u` `times` times (A5.1/A5.3).
    InsertKnot {
        /// Parameter value.
        u: f64,
        /// How many times.
        times: usize,
        /// Surface direction (U or V; Both is refused for surfaces).
        direction: Direction,
    },
    /// Knot refinement: insert every knot of `knots` (A5.4).
    Refine {
        /// The knots to insert (any order; repeated values insert repeatedly).
        knots: Vec<f64>,
        /// Surface direction (U or V; Both is refused for surfaces).
        direction: Direction,
    },
    /// Interval halving (seed 003): insert the midpoint of every non-degenerate knot span
    /// of the domain (A5.4 refinement; the shape is unchanged).
    Halve {
        /// Surface direction(s).
        direction: Direction,
    },
    /// Degree reduction by one (A5.11) when the deviation bound stays within `tolerance`;
    /// the bound reached is reported.
    Reduce {
        /// Largest accepted deviation (model units).
        tolerance: f64,
        /// Surface direction(s).
        direction: Direction,
    },
    /// Removal of every removable interior knot within `tolerance` (A5.8).
    RemoveKnots {
        /// Largest accepted total change (model units).
        tolerance: f64,
    },
    /// Bezier decomposition (A5.6/A5.7): one entity per segment or patch.
    Decompose,
    /// Split at a parameter into two entities (exact).
    Split {
        /// The parameter, strictly inside the domain.
        at: f64,
        /// Surface direction (U or V).
        direction: Direction,
    },
    /// Join all curves of the document, in order, into one (ends meeting within `tolerance`).
    Join {
        /// Largest accepted gap between an end and the next start.
        tolerance: f64,
    },
    /// Reverse the parameter direction (shape unchanged).
    Reverse {
        /// Surface direction(s).
        direction: Direction,
    },
    /// Affine change of parameter onto `[start, end]` (shape unchanged).
    Reparameterize {
        /// New domain start.
        start: f64,
        /// New domain end (> start).
        end: f64,
        /// Surface direction(s).
        direction: Direction,
    },
    /// Affine map of the poles `x' = R x + T` (IGES 5.3 entity 124 layout).
    Transform {
        /// The 3x4 matrix.
        matrix: crate::nurbs::transform::Affine,
    },
    /// The isoparametric curve of a surface at `u = at` (direction U) or `v = at` (V).
    Iso {
        /// The fixed parameter.
        at: f64,
        /// Which parameter is fixed (U or V).
        direction: Direction,
    },
    /// The periodic form (wrapped poles) of closed curves/surfaces whose seam is C^(p-1).
    Periodic {
        /// Largest accepted difference of the wrapped poles.
        tolerance: f64,
        /// Surface direction(s).
        direction: Direction,
    },
    /// The `order`-th derivative of a polynomial curve as a B-spline curve (A3.3).
    DerivativeCurve {
        /// Derivative order, 1..degree-1.
        order: usize,
    },
}

impl Operation {
    /// The surface direction(s) the operation works on (`Both` for the others).
    fn direction(&self) -> Direction {
        match self {
            Operation::Elevate { direction, .. }
            | Operation::Clamp { direction }
            | Operation::Unclamp { direction }
            | Operation::InsertKnot { direction, .. }
            | Operation::Refine { direction, .. }
            | Operation::Halve { direction }
            | Operation::Reduce { direction, .. }
            | Operation::Split { direction, .. }
            | Operation::Reverse { direction }
            | Operation::Reparameterize { direction, .. }
            | Operation::Iso { direction, .. }
            | Operation::Periodic { direction, .. } => *direction,
            Operation::RemoveKnots { .. }
            | Operation::Decompose
            | Operation::Join { .. }
            | Operation::Transform { .. }
            | Operation::DerivativeCurve { .. } => Direction::Both,
        }
    }

    /// Whether the result keeps the source's format metadata (flags, form, declared
    /// parameter range): only for operations that keep the geometry and its domain.
    fn keeps_meta(&self) -> bool {
        matches!(
            self,
            Operation::Elevate { .. }
                | Operation::Clamp { .. }
                | Operation::Unclamp { .. }
                | Operation::InsertKnot { .. }
                | Operation::Refine { .. }
                | Operation::Halve { .. }
                | Operation::Periodic { .. }
        )
    }

    /// Whether the result is still the kind of shape the source was (a circle stays a
    /// circle when split, reversed or moved; an iso-curve or a reduced curve is not).
    fn keeps_shape(&self) -> bool {
        self.keeps_meta()
            || matches!(
                self,
                Operation::Decompose
                    | Operation::Split { .. }
                    | Operation::Reverse { .. }
                    | Operation::Reparameterize { .. }
            )
    }
}

/// What an operation reports about one entity beyond the geometry: the deviation bound of
/// a reduction, the number of knots removed, the curves joined.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OpNote {
    /// The entity (its id before the operation).
    pub entity: String,
    /// What was done, in words.
    pub message: String,
    /// The bound of the geometric deviation the operation guarantees (model units), for
    /// the tolerance-bounded operations.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_bound: Option<f64>,
}

/// An output format for tessellation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (welded triangle meshes and polylines).
    Obj,
    /// Binary STL (triangles only).
    Stl,
    /// Binary glTF 2.0 (`.glb`: triangle meshes and line strips).
    Glb,
    /// An SVG picture (shaded isometric or top view, frame, scale bar, labels).
    Svg,
    /// The SVG picture rasterised to PNG.
    Png,
}

/// An evaluation request.
#[derive(Debug, Clone, Default)]
pub struct EvalRequest {
    /// Entity id (`#17`, `D5`, or the index for JSON input); `None`: the first entity.
    pub entity: Option<String>,
    /// `[u]` for curves, `[u, v]` for surfaces.
    pub params: Vec<Vec<f64>>,
    /// Highest derivative order (0: points only).
    pub derivatives: usize,
    /// Surface normals.
    pub normals: bool,
    /// Curvature.
    pub curvature: bool,
}

/// Finds an entity by id; `None` selects the first. The error lists the ids available.
pub fn select<'d>(doc: &'d Document, id: Option<&str>) -> Result<&'d Entity, PipelineError> {
    let found = match id {
        None => doc.entities.first(),
        Some(id) => doc.entities.iter().find(|e| is_entity(e, id)),
    };
    found.ok_or_else(|| {
        let ids: Vec<&str> = doc
            .entities
            .iter()
            .take(20)
            .map(|e| e.id.as_str())
            .collect();
        let message = match id {
            None => "the input holds no B-spline curve or surface".to_owned(),
            Some(id) => format!(
                "no entity {id}; the input holds {} entities: {}{}",
                doc.entities.len(),
                ids.join(", "),
                if doc.entities.len() > ids.len() {
                    ", ..."
                } else {
                    ""
                }
            ),
        };
        PipelineError::new(
            ErrorKind::Usage,
            "entity.not_found",
            message,
            Location::default(),
        )
    })
}

/// Writes a document in the given format, with the document's diagnostics untouched.
/// Returns the text and what the writer says about it, for the caller to report with the
/// document's diagnostics: for STEP, how it wrote the document's assembly (the plan the
/// writing follows, computed once; see [`drop_unwritable`]).
pub fn write(
    doc: &Document,
    format: Format,
    options: &ExportOptions,
) -> Result<(String, Vec<Diagnostic>), PipelineError> {
    exchange::write_reporting(doc, format, options).map_err(PipelineError::from_exchange)
}

/// What writing `doc` as `format` in `units` did, `doc` read as `kind` with `entities_in`
/// entities and its diagnostics holding the writer's: the report of [`convert`], without
/// verification. An operation on a file reports with it too.
pub fn file_report(
    kind: InputKind,
    format: Format,
    entities_in: usize,
    doc: &Document,
    units: LengthUnit,
) -> ConvertReport {
    ConvertReport {
        input_format: kind.name().to_owned(),
        output_format: format_name(format).to_owned(),
        entities_in,
        entities_out: doc.entities.len(),
        units: units_info(units),
        diagnostics: doc.diagnostics.clone(),
        verify: None,
        verify_part: None,
    }
}

/// Removes what a format cannot represent, with a warning per entity.
///
/// IGES has no parameter-space context outside a 142/508 (which nurbsx does not write): a
/// loose 2-D curve (a STEP pcurve, an IGES B(t) curve) would be read by every receiver as
/// a model-space curve in the plane z = 0, i.e. as stray geometry. So 2-D curves are not
/// written to IGES (warning `pcurve_not_written`). STEP keeps them, in a separate 2-D
/// representation that nurbsx reads back and CAD systems ignore.
///
/// STEP: an entity whose declared kind (a circle, a cylinder...) its geometry does not
/// agree with is written with `.UNSPECIFIED.` form, with a warning each
/// (`exchange::step::form_warnings`).
///
/// An assembly (read with its placements applied) is written to STEP with its product
/// structure (each part once, placed by its instances) unless the export options ask for it
/// flattened; instances whose placement an axis placement cannot carry are written
/// flattened with a warning. The STEP writer decides that while writing, so [`write()`]
/// returns those warnings (`exchange::step::write_reporting`), not this function. IGES
/// output has subfigures (308/408) that nurbsx does not write: there the assembly is written
/// flattened, a warning (`assembly.flattened`), as the product and instance names and the
/// sharing of parts are lost for the user.
pub fn drop_unwritable(doc: &mut Document, format: Format) {
    let instances = doc.topology.instances.len();
    if instances > 0 && format == Format::Iges {
        let message = format!(
            "assembly written flattened (IGES subfigures are not written): {instances} instance(s) written as their placed solids, shells and faces in root coordinates ({} solid(s), {} face(s)); the product structure (products, instances and their names) is not written",
            doc.topology.model.solids.len(),
            doc.topology.model.faces.len()
        );
        doc.diagnostics.push(Diagnostic::warning(
            "assembly.flattened",
            message,
            Location::default(),
        ));
    }
    if format == Format::Step {
        let warnings = crate::exchange::step::form_warnings(doc);
        doc.diagnostics.extend(warnings);
        // Declared parameter ranges of free geometry have no STEP counterpart: say so.
        let ranges = crate::exchange::step::range_warnings(doc);
        doc.diagnostics.extend(ranges);
    }
    if format != Format::Iges {
        return;
    }
    // Kinds (a circle, a cylinder ...) whose geometry fails the form check are written as
    // form 0: say so.
    let forms = exchange::iges::form_warnings(doc);
    doc.diagnostics.extend(forms);
    // Declared parameter ranges outside the knot domain are written clipped to it: say so.
    let ranges = exchange::iges::range_warnings(doc);
    doc.diagnostics.extend(ranges);
    // A 2-D curve that a face's boundary uses (IGES 142/508, STEP pcurve) is carried on its
    // coedge when the document has topology: not dropped.
    let carried = !doc.topology.is_empty();
    let (dropped, kept): (Vec<Entity>, Vec<Entity>) = std::mem::take(&mut doc.entities)
        .into_iter()
        .partition(|e| {
            e.geometry.dimension() == 2
                && matches!(e.geometry, Geometry::Curve(_))
                && (!carried || e.meta.used_by.is_empty())
        });
    if let Some(first) = dropped.first() {
        doc.diagnostics.push(Diagnostic::warning(
            "pcurve_not_written",
            format!(
                "{} 2-D parameter-space curve(s) not written ({}): IGES output has no place for \
                 them outside a trimmed surface",
                dropped.len(),
                id_list(dropped.iter())
            ),
            Location::at_entity(first.id.clone()),
        ));
    }
    doc.entities = kept;
}

/// The first eight ids of some entities, `, ...` when there are more: `#37, #50, ...`.
pub(super) fn id_list<'e>(entities: impl ExactSizeIterator<Item = &'e Entity>) -> String {
    let more = entities.len() > 8;
    let ids: Vec<&str> = entities.take(8).map(|e| e.id.as_str()).collect();
    format!("{}{}", ids.join(", "), if more { ", ..." } else { "" })
}

/// Reads, optionally clamps or unclamps, writes, and optionally verifies by re-reading.
pub fn convert(
    bytes: &[u8],
    hint: Option<InputKind>,
    request: &ConvertRequest,
    settings: &Settings,
) -> Result<ConvertOutput, PipelineError> {
    let Loaded { kind, mut document } = load(bytes, hint, settings)?;
    let format = request.to.or(kind.format()).ok_or_else(|| {
        PipelineError::usage(
            "convert.no_target",
            "model JSON input needs an output format (--to step|iges)",
        )
    })?;
    if document.entities.is_empty() {
        return Err(PipelineError::new(
            ErrorKind::Invalid,
            "convert.empty",
            format!(
                "the input holds no readable B-spline curve or surface ({} diagnostics)",
                document.diagnostics.len()
            ),
            Location::default(),
        ));
    }
    let op = match request.clamp {
        ClampPolicy::Keep => None,
        ClampPolicy::Clamp => Some(Operation::Clamp {
            direction: Direction::Both,
        }),
        ClampPolicy::Unclamp => Some(Operation::Unclamp {
            direction: Direction::Both,
        }),
    };
    let entities_in = document.entities.len();
    drop_unwritable(&mut document, format);
    settings.cancel.check()?;
    let original = op.is_some().then(|| document.clone());
    if let Some(op) = op {
        apply(&mut document, op, None, settings)?;
    }
    check_file_reply(&document, settings)?;
    let export = ExportOptions {
        cancel: settings.cancel.clone(),
        ..request.export.clone()
    };
    let (text, written) = write(&document, format, &export)?;
    document.diagnostics.extend(written);
    settings.cancel.check()?;
    let out_units = request.export.units.unwrap_or(document.units);
    let (verify, verify_part) = match request.verify {
        None => (None, None),
        Some(tolerance) => {
            let reference = original.as_ref().unwrap_or(&document);
            let (entities, part) = verify_output(reference, &text, out_units, tolerance, settings)?;
            (Some(entities), part)
        }
    };
    let mut report = file_report(kind, format, entities_in, &document, out_units);
    if let Some(devs) = &verify {
        for d in devs.iter().filter(|d| !d.ok) {
            report.diagnostics.push(Diagnostic::error(
                "verify.deviation",
                format!(
                    "re-read entity {} deviates by {:e} (relative {:e}) from input {}",
                    d.output_id, d.max_deviation, d.relative, d.input_id
                ),
                Location::at_entity(d.input_id.clone()),
            ));
        }
    }
    report.verify = verify;
    report.verify_part = verify_part;
    if let Some(p) = report
        .verify_part
        .as_ref()
        .filter(|p| p.unmeasured_faces > 0)
    {
        report.diagnostics.push(Diagnostic::warning(
            "verify.unmeasured",
            format!(
                "{} face(s) of the input and the output have no parameter-space boundary, so \
                 the trimmed areas, volumes and centroids are not compared (faces and solids \
                 are counted)",
                p.unmeasured_faces
            ),
            Location::default(),
        ));
    }
    if let Some(p) = report.verify_part.as_ref().filter(|p| !p.ok) {
        return Err(PipelineError::new(
            ErrorKind::Geometry,
            "verify.failed",
            format!(
                "verification failed: faces {} -> {}, solids {} -> {}, area {:e} -> {:e} \
                 (relative {:e}), volume {:e} -> {:e} (relative {:e}), centroid moved {:e} of \
                 the part's size, {} face(s) not measurable (tolerance {:e})",
                p.faces_in,
                p.faces_out,
                p.solids_in,
                p.solids_out,
                p.area_in,
                p.area_out,
                p.area_relative,
                p.volume_in,
                p.volume_out,
                p.volume_relative,
                p.centroid_relative,
                p.unmeasured_faces,
                request.verify.unwrap_or_default()
            ),
            Location::default(),
        ));
    }
    if let Some(bad) = report
        .verify
        .as_ref()
        .and_then(|v| v.iter().find(|d| !d.ok))
    {
        return Err(PipelineError::new(
            ErrorKind::Geometry,
            "verify.failed",
            format!(
                "verification failed: entity {} deviates by {:e} relative (tolerance {:e})",
                bad.input_id,
                bad.relative,
                request.verify.unwrap_or_default()
            ),
            Location::at_entity(bad.input_id.clone()),
        ));
    }
    Ok(ConvertOutput {
        format,
        text,
        report,
    })
}

/// Re-reads written text and compares every entity with the one it came from by sampling.
fn verify_output(
    reference: &Document,
    text: &str,
    out_units: LengthUnit,
    tolerance: f64,
    settings: &Settings,
) -> Result<(Vec<EntityDeviation>, Option<PartDeviation>), PipelineError> {
    let reread = exchange::read(text.as_bytes(), &settings.import).map_err(|d| {
        PipelineError::new(
            ErrorKind::Geometry,
            "verify.unreadable",
            format!("the output does not read back: {d}"),
            d.location.clone(),
        )
    })?;
    let scale = reference.units.to_mm() / out_units.to_mm();
    let part = (!reference.topology.is_empty())
        .then(|| part_deviation(reference, &reread, scale, tolerance));
    // With faces, what a CAD system sees is compared (faces, solids, area, volume,
    // centroid): the writers re-derive the geometry-level view of face surfaces, edge
    // curves and pcurves, so entity lists differ in count and order between formats.
    if part.is_some() {
        return Ok((Vec::new(), part));
    }
    let (ours, theirs): (Vec<&Entity>, Vec<&Entity>) = (
        reference.entities.iter().collect(),
        reread.entities.iter().collect(),
    );
    if ours.len() != theirs.len() {
        return Err(PipelineError::new(
            ErrorKind::Geometry,
            "verify.count",
            format!(
                "wrote {} entities but read back {}",
                ours.len(),
                theirs.len()
            ),
            Location::default(),
        ));
    }
    let entities = ours
        .iter()
        .zip(&theirs)
        .map(|(a, b)| {
            settings.cancel.check()?;
            let (max, size) = sampled_deviation(&a.geometry, &b.geometry, scale);
            let relative = max / size.max(f64::MIN_POSITIVE);
            Ok(EntityDeviation {
                input_id: a.id.to_string(),
                output_id: b.id.to_string(),
                max_deviation: max,
                relative,
                ok: relative <= tolerance,
            })
        })
        .collect::<Result<Vec<_>, PipelineError>>()?;
    Ok((entities, part))
}

/// Faces, trimmed area, centroid, solids and volume of the input (scaled to the output
/// unit) against the re-read output.
fn part_deviation(
    reference: &Document,
    reread: &Document,
    scale: f64,
    tolerance: f64,
) -> PartDeviation {
    let (a, b) = (
        reference.topology.model.totals(),
        reread.topology.model.totals(),
    );
    let volume = |t: &crate::topology::Totals| -> f64 {
        t.volumes.iter().filter_map(|v| v.as_ref().ok()).sum()
    };
    let (area_in, area_out) = (a.area * scale * scale, b.area);
    let (volume_in, volume_out) = (volume(&a) * scale.powi(3), volume(&b));
    let relative = |x: f64, y: f64| {
        if x == 0.0 && y == 0.0 {
            0.0
        } else {
            (y - x).abs() / x.abs().max(f64::MIN_POSITIVE)
        }
    };
    let size = reference
        .topology
        .model
        .faces
        .iter()
        .map(|f| bounding_box_diagonal(f.surface.control_points().as_slice()))
        .fold(0.0, f64::max)
        * scale;
    let centroid_relative = if area_in > 0.0 && area_out > 0.0 {
        distance(a.centroid.map(|x| x * scale), b.centroid) / size.max(f64::MIN_POSITIVE)
    } else {
        0.0
    };
    let (faces_in, faces_out) = (
        reference.topology.model.faces.len(),
        reread.topology.model.faces.len(),
    );
    let (solids_in, solids_out) = (
        reference.topology.model.solids.len(),
        reread.topology.model.solids.len(),
    );
    let area_relative = relative(area_in, area_out);
    let volume_relative = relative(volume_in, volume_out);
    let unmeasured_faces = a.unmeasured + b.unmeasured;
    PartDeviation {
        faces_in,
        faces_out,
        area_in,
        area_out,
        area_relative,
        solids_in,
        solids_out,
        volume_in,
        volume_out,
        volume_relative,
        centroid_relative,
        unmeasured_faces,
        // Faces that cannot be measured (no pcurve) are counted, and said in a warning, but
        // the figures compare the measured ones.
        measured: unmeasured_faces == 0,
        ok: faces_in == faces_out
            && solids_in == solids_out
            && (unmeasured_faces > 0
                || (area_relative <= tolerance
                    && volume_relative <= tolerance
                    && centroid_relative <= tolerance)),
    }
}

/// Largest distance between `a` (scaled by `scale`) and `b` at the same normalised
/// parameters (65 on curves, 17 x 17 on surfaces), and the size of `b`'s control box.
fn sampled_deviation(a: &Geometry, b: &Geometry, scale: f64) -> (f64, f64) {
    let lerp = |(s, e): (f64, f64), f: f64| s + (e - s) * f;
    let scaled = |p: Point3| [p[0] * scale, p[1] * scale, p[2] * scale];
    match (a, b) {
        (Geometry::Curve(a), Geometry::Curve(b)) => {
            let mut worst: f64 = 0.0;
            for k in 0..=64 {
                let f = f64::from(k) / 64.0;
                let pa = scaled(a.point_at_unchecked(lerp(a.domain(), f)));
                let pb = b.point_at_unchecked(lerp(b.domain(), f));
                worst = worst.max(distance(pa, pb));
            }
            (worst, bounding_box_diagonal(b.control_points()))
        }
        (Geometry::Surface(a), Geometry::Surface(b)) => {
            let mut worst: f64 = 0.0;
            let ((au, av), (bu, bv)) = (a.domain(), b.domain());
            for i in 0..=16 {
                for j in 0..=16 {
                    let (fu, fv) = (f64::from(i) / 16.0, f64::from(j) / 16.0);
                    let pa = scaled(a.point_at_unchecked(lerp(au, fu), lerp(av, fv)));
                    let pb = b.point_at_unchecked(lerp(bu, fu), lerp(bv, fv));
                    worst = worst.max(distance(pa, pb));
                }
            }
            (worst, bounding_box_diagonal(b.control_points().as_slice()))
        }
        _ => (f64::INFINITY, 1.0),
    }
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Step => "step",
        Format::Iges => "iges",
    }
}

fn units_info(u: LengthUnit) -> UnitsInfo {
    UnitsInfo {
        name: u.short_name().to_owned(),
        to_mm: u.to_mm(),
    }
}

/// Everything `nurbsx info` shows.
pub fn info(loaded: &Loaded) -> InfoReport {
    let doc = &loaded.document;
    InfoReport {
        format: loaded.kind.name().to_owned(),
        schema: doc.schema.clone(),
        units: units_info(doc.units),
        entities: {
            let roles = entity_roles(doc);
            doc.entities
                .iter()
                .map(|e| entity_info(e, roles.get(e.id.as_str()).copied().unwrap_or("free")))
                .collect()
        },
        structure: structure_info(doc),
        diagnostics: doc.diagnostics.clone(),
    }
}

/// The boundary representation with every face measured (`None` without one).
fn structure_info(doc: &Document) -> Option<StructureInfo> {
    if doc.topology.is_empty() {
        return None;
    }
    let (m, o) = (&doc.topology.model, &doc.topology.origins);
    let totals = m.totals();
    let id = |v: &[exchange::Origin], i: usize| {
        v.get(i).map_or_else(|| i.to_string(), |x| x.id.to_string())
    };
    // By id once (a search per face would be quadratic on a large part).
    let by_id: std::collections::HashMap<&str, &Entity> =
        doc.entities.iter().map(|e| (e.id.as_str(), e)).collect();
    let shape_of = |entity: &Option<exchange::Label>| {
        entity
            .as_deref()
            .and_then(|e| by_id.get(e))
            .and_then(|x| x.meta.shape)
    };
    let faces = m
        .faces
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let origin = o.faces.get(i);
            let measured = &totals.faces[i];
            FaceInfo {
                id: id(&o.faces, i),
                surface: origin.and_then(|x| x.entity.as_ref().map(|e| e.to_string())),
                shape: origin.and_then(|x| shape_of(&x.entity)),
                loops: f.loops.len(),
                edges: f.loops.iter().map(|l| l.coedges.len()).sum(),
                same_sense: f.same_sense,
                area: measured.as_ref().ok().map(|x| x.area),
                area_error: measured.as_ref().err().map(ToString::to_string),
            }
        })
        .collect();
    let shells = m
        .shells
        .iter()
        .enumerate()
        .map(|(i, s)| ShellInfo {
            id: id(&o.shells, i),
            closed: s.closed,
            faces: s.faces.len(),
            face_ids: s.faces.iter().map(|(f, _)| id(&o.faces, f.0)).collect(),
        })
        .collect();
    let solids = m
        .solids
        .iter()
        .enumerate()
        .map(|(i, s)| SolidInfo {
            id: id(&o.solids, i),
            name: o.solids.get(i).and_then(|x| x.name.clone()),
            shells: 1 + s.voids.len(),
            shell_ids: std::iter::once(&s.outer)
                .chain(&s.voids)
                .map(|sh| id(&o.shells, sh.0))
                .collect(),
            faces: std::iter::once(&s.outer)
                .chain(&s.voids)
                .filter_map(|sh| m.shells.get(sh.0))
                .map(|sh| sh.faces.len())
                .sum(),
            volume: totals.volumes[i].as_ref().ok().copied(),
        })
        .collect();
    Some(StructureInfo {
        solids,
        shells,
        faces,
        edges: m.edges.len(),
        vertices: m.vertices.len(),
        assemblies: m.assemblies.len(),
        instances: doc.topology.instances.clone(),
        area: totals.area,
        centroid: (totals.area > 0.0).then_some(totals.centroid),
        unmeasured_faces: totals.unmeasured,
    })
}

/// The role of every entity the topology uses, by id (the others are free): face
/// surfaces, edge curves, the 3-D curves a face boundary used (`meta.used_by`: the
/// boundary's copy of an edge, as both sides of an IGES 144 seam before sewing), and the
/// 2-D curves, which in a part are parameter-space curves of face boundaries (an IGES 508
/// names them without `used_by`).
fn entity_roles(doc: &Document) -> std::collections::HashMap<&str, &'static str> {
    let o = &doc.topology.origins;
    let mut roles = std::collections::HashMap::new();
    if doc.topology.is_empty() {
        return roles;
    }
    for e in &doc.entities {
        if let Geometry::Curve(c) = &e.geometry {
            if c.dimension() == 2 {
                roles.insert(e.id.as_str(), "pcurve");
            } else if !e.meta.used_by.is_empty() {
                roles.insert(e.id.as_str(), "edge");
            }
        }
    }
    for x in &o.edges {
        if let Some(id) = &x.entity {
            roles.insert(id.as_str(), "edge");
        }
    }
    for x in &o.faces {
        if let Some(id) = &x.entity {
            roles.insert(id.as_str(), "face");
        }
    }
    roles
}

fn entity_info(e: &Entity, role: &'static str) -> EntityInfo {
    match &e.geometry {
        Geometry::Curve(c) => EntityInfo {
            id: e.id.to_string(),
            kind: "curve",
            dimension: c.dimension(),
            degree: vec![c.degree()],
            poles: vec![c.num_poles()],
            rational: c.is_rational(),
            layout: vec![
                c.layout(layout_tolerance(c.control_points()))
                    .name()
                    .to_owned(),
            ],
            domain: vec![c.domain()],
            geometry: e.geometry.clone(),
            source: e.source.clone(),
            role,
        },
        Geometry::Surface(s) => {
            let net = s.control_points();
            let (du, dv) = s.domain();
            EntityInfo {
                id: e.id.to_string(),
                kind: "surface",
                dimension: s.dimension(),
                degree: vec![s.degree_u(), s.degree_v()],
                poles: vec![net.nu(), net.nv()],
                rational: s.is_rational(),
                layout: {
                    let tol = layout_tolerance(net.as_slice());
                    vec![
                        s.layout_u(tol).name().to_owned(),
                        s.layout_v(tol).name().to_owned(),
                    ]
                },
                domain: vec![du, dv],
                geometry: e.geometry.clone(),
                source: e.source.clone(),
                role,
            }
        }
    }
}

/// Geometric tolerance for recognising wrapped (periodic) poles: 1e-10 of the control
/// polygon's size, far below any modelling tolerance and far above the rounding of poles
/// written with 12+ significant digits.
fn layout_tolerance(points: &[Point3]) -> f64 {
    1e-10 * bounding_box_diagonal(points).max(f64::MIN_POSITIVE)
}

/// Validates input: does it conform to its standard? Parse and geometry diagnostics, where
/// every violation of the standard is an error (also those the reader read anyway, which
/// reading reports as warnings); a file that cannot be read at all is one error diagnostic.
pub fn validate(
    bytes: &[u8],
    hint: Option<InputKind>,
    strict: bool,
    settings: &Settings,
) -> ValidationReport {
    let mut settings = settings.clone();
    settings.import.conformance = true;
    match load(bytes, hint, &settings) {
        Ok(loaded) => ValidationReport::new(
            loaded.document.entities.len(),
            loaded
                .document
                .diagnostics
                .into_iter()
                .map(Diagnostic::for_conformance)
                .collect(),
            strict,
        ),
        Err(e) => ValidationReport::new(0, vec![e.diagnostic], strict),
    }
}

/// Evaluates one entity at the requested parameters: points, derivatives up to
/// `request.derivatives` (curves: `derivatives[k-1]` is the k-th derivative; surfaces: an
/// object keyed `"u"`, `"v"`, `"uu"`, `"uv"`, `"vv"`, ...), normals (surfaces: the unit normal,
/// with the limit normal at degenerate points; curves: the Frenet principal normal, absent
/// where the curvature is 0) and curvature (curves: curvature, torsion, osculating circle;
/// surfaces: Gaussian, mean and principal curvatures with directions). A point where a
/// differential quantity does not exist gets `{"error": ...}` for it; the point itself and
/// the other results are still returned.
pub fn evaluate(
    doc: &Document,
    request: &EvalRequest,
    settings: &Settings,
) -> Result<EvalReport, PipelineError> {
    let mut results = Vec::with_capacity(request.params.len());
    let entity = evaluate_each(
        doc,
        request,
        request.params.iter().map(Vec::as_slice),
        settings,
        |r| {
            results.push(r);
            Ok(())
        },
    )?;
    Ok(EvalReport {
        entity: entity.id.to_string(),
        results,
    })
}

/// [`evaluate`] at `params` (in place of `request.params`, which is not read), handing
/// each result to `each` in order instead of collecting them: the service streams them
/// ([`EvalReport`]'s JSON written result by result), so its memory does not grow with the
/// parameter count. Stops at the first error of `each`. The entity evaluated.
pub fn evaluate_each<'d, 'p>(
    doc: &'d Document,
    request: &EvalRequest,
    params: impl ExactSizeIterator<Item = &'p [f64]>,
    settings: &Settings,
    mut each: impl FnMut(EvalResult) -> Result<(), PipelineError>,
) -> Result<&'d Entity, PipelineError> {
    use serde_json::{Map, Value, json};
    let entity = check_evaluation(doc, request, params.len(), settings)?;
    let dim = entity.geometry.dimension();
    let coords = |p: Point3| -> Value { json!(p[..dim]) };
    let failure = |e: crate::nurbs::GeometryError| json!({ "error": e.to_string() });
    let at_error = |e: crate::nurbs::GeometryError| {
        PipelineError::new(
            ErrorKind::Usage,
            "evaluate.domain",
            e.to_string(),
            Location::at_entity(entity.id.clone()),
        )
    };
    for (k, at) in params.enumerate() {
        if k % EVAL_POLL == 0 {
            settings.cancel.check()?;
        }
        let result = match (&entity.geometry, at) {
            (Geometry::Curve(c), &[u]) => {
                let u = snap_to_domain(u, c.domain());
                let ders = c.derivatives(u, request.derivatives).map_err(at_error)?;
                let derivatives = (request.derivatives > 0)
                    .then(|| Value::Array(ders[1..].iter().map(|&d| coords(d)).collect()));
                let normal = if request.normals {
                    c.frenet_frame(u).ok().and_then(|f| f.normal)
                } else {
                    None
                };
                let curvature = request.curvature.then(|| match c.curvature(u) {
                    Err(e) => failure(e),
                    Ok(k) => {
                        let circle = c.osculating_circle(u).ok().flatten();
                        json!({
                            "curvature": k.curvature,
                            "signed_curvature": k.signed_curvature,
                            "torsion": k.torsion,
                            "osculating_circle": circle.map(|o| json!({
                                "center": coords(o.center),
                                "radius": o.radius,
                                "normal": o.normal,
                            })),
                        })
                    }
                });
                EvalResult {
                    at: at.to_vec(),
                    point: ders[0][..dim].to_vec(),
                    derivatives,
                    normal,
                    curvature,
                }
            }
            (Geometry::Surface(s), &[u, v]) => {
                let (du, dv) = s.domain();
                let (u, v) = (snap_to_domain(u, du), snap_to_domain(v, dv));
                let skl = s.derivatives(u, v, request.derivatives).map_err(at_error)?;
                let derivatives = (request.derivatives > 0).then(|| {
                    let mut map = Map::new();
                    for order in 1..=request.derivatives {
                        for k in (0..=order).rev() {
                            let l = order - k;
                            let key = format!("{}{}", "u".repeat(k), "v".repeat(l));
                            map.insert(key, coords(skl[k][l]));
                        }
                    }
                    Value::Object(map)
                });
                let normal = if request.normals {
                    Some(s.normal(u, v).map_err(|e| {
                        PipelineError::new(
                            ErrorKind::Geometry,
                            "evaluate.normal",
                            format!("no normal at ({u}, {v}): {e}"),
                            Location::at_entity(entity.id.clone()),
                        )
                    })?)
                } else {
                    None
                };
                let curvature = request.curvature.then(|| match s.curvature(u, v) {
                    Err(e) => failure(e),
                    Ok(k) => json!({
                        "gaussian": k.gaussian,
                        "mean": k.mean,
                        "k1": k.k1,
                        "k2": k.k2,
                        "dir1": k.dir1,
                        "dir2": k.dir2,
                        "umbilic": k.umbilic,
                    }),
                });
                EvalResult {
                    at: at.to_vec(),
                    point: skl[0][0][..dim].to_vec(),
                    derivatives,
                    normal,
                    curvature,
                }
            }
            (g, _) => {
                let curve = matches!(g, Geometry::Curve(_));
                return Err(PipelineError::usage(
                    "evaluate.arity",
                    format!(
                        "{} {} takes {} parameter(s) per point, got {:?}",
                        if curve { "curve" } else { "surface" },
                        entity.id,
                        if curve { 1 } else { 2 },
                        at
                    ),
                ));
            }
        };
        each(result)?;
    }
    Ok(entity)
}

/// The checks [`evaluate`] makes before any work, for `count` parameters (the caller may
/// hold them in another form until they pass): the point limit, the derivative order, the
/// entity, and the reply estimate against [`Settings::max_reply_bytes`]. The entity.
pub fn check_evaluation<'d>(
    doc: &'d Document,
    request: &EvalRequest,
    count: usize,
    settings: &Settings,
) -> Result<&'d Entity, PipelineError> {
    if count > settings.max_eval_points {
        return Err(PipelineError::new(
            ErrorKind::Limit,
            "limit.eval_points",
            format!(
                "{count} parameters requested, above the limit of {}",
                settings.max_eval_points
            ),
            Location::default(),
        ));
    }
    if request.derivatives > crate::nurbs::derivatives::MAX_DERIVATIVE_ORDER {
        return Err(PipelineError::usage(
            "evaluate.order",
            format!(
                "derivative order {} is above the supported {}",
                request.derivatives,
                crate::nurbs::derivatives::MAX_DERIVATIVE_ORDER
            ),
        ));
    }
    let entity = select(doc, request.entity.as_deref())?;
    check_reply(
        count as f64 * eval_result_bytes(&entity.geometry, request),
        "evaluation reply",
        "ask for fewer parameters or fewer quantities per point",
        settings,
    )?;
    Ok(entity)
}

/// Evaluations between two polls of the stop signal.
const EVAL_POLL: usize = 1024;

/// An upper estimate of one evaluation result's JSON text: the parameters and the point,
/// then per derivative order the vectors it adds (curves 1, surfaces `order + 1` with
/// their keys), the normal, and the curvature record (at most 12 numbers with keys).
fn eval_result_bytes(g: &Geometry, request: &EvalRequest) -> f64 {
    let dim = g.dimension() as f64;
    let (arity, curve) = match g {
        Geometry::Curve(_) => (1.0, true),
        Geometry::Surface(_) => (2.0, false),
    };
    let vector = dim * NUMBER_BYTES + 4.0;
    let mut bytes = 24.0 + (arity + dim) * NUMBER_BYTES;
    for order in 1..=request.derivatives {
        bytes += if curve {
            vector
        } else {
            (order as f64 + 1.0) * (vector + order as f64 + 3.0)
        };
    }
    if request.derivatives > 0 {
        bytes += 16.0;
    }
    if request.normals {
        bytes += 3.0 * NUMBER_BYTES + 12.0;
    }
    if request.curvature {
        bytes += 12.0 * NUMBER_BYTES + 160.0;
    }
    bytes
}

/// Applies an operation to one entity (`entity = Some(id)`) or to all, and says what it
/// did beyond the geometry ([`OpNote`]: the bound of a reduction, the knots removed ...).
///
/// An operation that makes several entities of one (decompose, split) names them
/// `<id>.1`, `<id>.2`, ...; [`Operation::Join`] replaces all curves by one (named after the
/// first) and refuses `entity`. Operations that do not keep the domain or the geometry
/// drop the source's format flags, keeping the name (and the shape kind where it holds).
pub fn apply(
    doc: &mut Document,
    op: Operation,
    entity: Option<&str>,
    settings: &Settings,
) -> Result<Vec<OpNote>, PipelineError> {
    if let Some(id) = entity {
        select(doc, Some(id))?;
    }
    if let Operation::Elevate { by, direction } = op {
        if (1..=settings.max_elevate_by).contains(&by) {
            // The result's size is known before the work (A5.9): refuse a too large one now.
            check_reply(
                estimated_file_bytes(doc, Some((by, direction, entity))),
                "elevated file",
                "elevate fewer entities, one direction, or by less",
                settings,
            )?;
        }
    }
    check_growth(doc, &op, entity, settings)?;
    if let Operation::Join { tolerance } = op {
        if entity.is_some() {
            return Err(PipelineError::usage(
                "join.entity",
                "join works on all curves of the input, in order; it takes no entity",
            ));
        }
        let note = join_curves(doc, tolerance)?;
        drop_topology(doc);
        return Ok(vec![note]);
    }
    let mut notes = Vec::new();
    let mut out = Vec::with_capacity(doc.entities.len());
    // The document is replaced only when every entity succeeded: an error leaves it as
    // it was.
    for e in &doc.entities {
        if entity.is_some_and(|id| !is_entity(e, id)) {
            out.push(e.clone());
            continue;
        }
        settings.cancel.check()?;
        let (geometries, note) =
            apply_one(&e.geometry, &op, settings).map_err(|err| PipelineError {
                diagnostic: Diagnostic {
                    location: Location::at_entity(e.id.clone()),
                    ..err.diagnostic
                },
                ..err
            })?;
        if let Some((message, error_bound)) = note {
            notes.push(OpNote {
                entity: e.id.to_string(),
                message,
                error_bound,
            });
        }
        let meta = if op.keeps_meta() {
            e.meta.clone()
        } else {
            exchange::Meta {
                name: e.meta.name.clone(),
                shape: e.meta.shape.filter(|_| op.keeps_shape()),
                ..Default::default()
            }
        };
        let several = geometries.len() > 1;
        for (k, geometry) in geometries.into_iter().enumerate() {
            out.push(Entity {
                id: if several {
                    compact_str::format_compact!("{}.{}", e.id, k + 1)
                } else {
                    e.id.clone()
                },
                geometry,
                source: e.source.clone(),
                meta: meta.clone(),
            });
        }
    }
    doc.entities = out;
    drop_topology(doc);
    Ok(notes)
}

/// Operations work on the curves and surfaces one by one; the faces, edges and solids
/// built on them are not carried through (warning, visible by default).
fn drop_topology(doc: &mut Document) {
    if doc.topology.is_empty() {
        return;
    }
    let m = &doc.topology.model;
    // The assembly's part definitions are dropped with the model they were placed into, so
    // that no writer writes definitions the operation did not change.
    let assembly = if doc.topology.structure.is_some() {
        format!(
            " and the assembly's product structure ({} instance(s))",
            doc.topology.instances.len()
        )
    } else {
        String::new()
    };
    let pcurves = m
        .faces
        .iter()
        .flat_map(|f| &f.loops)
        .flat_map(|l| &l.coedges)
        .filter(|c| c.pcurve.is_some())
        .count();
    let message = format!(
        "the operation works on curves and surfaces: the boundary representation ({} solid(s), {} shell(s), {} face(s), {} edge(s), {pcurves} coedge pcurve(s)){assembly} is not carried to the output, whose faces are written as untrimmed surfaces",
        m.solids.len(),
        m.shells.len(),
        m.faces.len(),
        m.edges.len()
    );
    doc.topology = Default::default();
    doc.diagnostics.push(Diagnostic::warning(
        "topology.dropped",
        message,
        Location::default(),
    ));
}

/// Refuses, before the work, an operation whose result would exceed the reply limit:
/// Bezier decomposition (each of the `s` spans gets `p + 1` poles per direction),
/// refinement (one pole per inserted knot and row) and halving (one pole per span).
fn check_growth(
    doc: &Document,
    op: &Operation,
    entity: Option<&str>,
    settings: &Settings,
) -> Result<(), PipelineError> {
    let spans = |knots: &[f64], p: usize| -> f64 {
        knots
            .get(p..knots.len().saturating_sub(p))
            .map_or(0, |d| d.windows(2).filter(|w| w[1] > w[0]).count()) as f64
    };
    let per_pole = 4.0 * NUMBER_BYTES + 30.0;
    let bytes: f64 = match op {
        Operation::Decompose => doc
            .entities
            .iter()
            .filter(|e| entity.is_none_or(|id| is_entity(e, id)))
            .map(|e| match &e.geometry {
                Geometry::Curve(c) => {
                    let s = spans(c.knots(), c.degree());
                    s * (256.0 + (c.degree() + 1) as f64 * (per_pole + 2.0 * NUMBER_BYTES))
                }
                Geometry::Surface(s) => {
                    let (su, sv) = (
                        spans(s.knots_u(), s.degree_u()),
                        spans(s.knots_v(), s.degree_v()),
                    );
                    let poles = ((s.degree_u() + 1) * (s.degree_v() + 1)) as f64;
                    su * sv * (256.0 + poles * per_pole)
                }
            })
            .sum(),
        Operation::Refine { knots, .. } => {
            let rows: f64 = doc
                .entities
                .iter()
                .filter(|e| entity.is_none_or(|id| is_entity(e, id)))
                .map(|e| match &e.geometry {
                    Geometry::Curve(_) => 1.0,
                    Geometry::Surface(s) => {
                        s.control_points().nu().max(s.control_points().nv()) as f64
                    }
                })
                .sum();
            estimated_file_bytes(doc, None) + knots.len() as f64 * (rows * per_pole + NUMBER_BYTES)
        }
        // One more pole per halved span: at most twice the poles per direction.
        Operation::Halve { direction } => {
            let factor = if *direction == Direction::Both {
                4.0
            } else {
                2.0
            };
            estimated_file_bytes(doc, None) * factor
        }
        _ => return Ok(()),
    };
    check_reply(
        bytes,
        "result",
        "work on fewer or smaller entities",
        settings,
    )
}

/// Joins every curve of the document, in order, into one (A5.1 clamping at the junctions,
/// see [`crate::nurbs::NurbsCurve::join`]); surfaces are kept as they are.
fn join_curves(doc: &mut Document, tolerance: f64) -> Result<OpNote, PipelineError> {
    let curves: Vec<usize> = doc
        .entities
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(e.geometry, Geometry::Curve(_)))
        .map(|(i, _)| i)
        .collect();
    let [first, rest @ ..] = curves.as_slice() else {
        return Err(PipelineError::usage(
            "join.count",
            "join needs at least two curves; the input holds none",
        ));
    };
    if rest.is_empty() {
        return Err(PipelineError::usage(
            "join.count",
            "join needs at least two curves; the input holds one",
        ));
    }
    let Geometry::Curve(mut joined) = doc.entities[*first].geometry.clone() else {
        return Err(PipelineError::usage("join.count", "join needs curves"));
    };
    for &i in rest {
        if let Geometry::Curve(next) = &doc.entities[i].geometry {
            joined = joined.join(next, tolerance).map_err(|err| {
                let err = PipelineError::from(err);
                PipelineError {
                    diagnostic: Diagnostic {
                        location: Location::at_entity(doc.entities[i].id.clone()),
                        ..err.diagnostic
                    },
                    ..err
                }
            })?;
        }
    }
    let ids = id_list(curves.iter().map(|&i| &doc.entities[i]));
    let first_id = doc.entities[*first].id.to_string();
    let name = doc.entities[*first].meta.name.clone();
    let source = doc.entities[*first].source.clone();
    let mut kept = Vec::with_capacity(doc.entities.len() - rest.len());
    for (i, e) in std::mem::take(&mut doc.entities).into_iter().enumerate() {
        if i == *first {
            kept.push(Entity {
                id: first_id.as_str().into(),
                geometry: Geometry::Curve(joined.clone()),
                source: source.clone(),
                meta: exchange::Meta {
                    name: name.clone(),
                    ..Default::default()
                },
            });
        } else if !curves.contains(&i) {
            kept.push(e);
        }
    }
    doc.entities = kept;
    Ok(OpNote {
        entity: first_id,
        message: format!("joined {} curves ({ids}) into one", curves.len()),
        error_bound: None,
    })
}

/// A note of [`apply_one`]: the message and, for tolerance-bounded operations, the bound.
type Note = Option<(String, Option<f64>)>;

fn apply_one(
    g: &Geometry,
    op: &Operation,
    settings: &Settings,
) -> Result<(Vec<Geometry>, Note), PipelineError> {
    use crate::nurbs::clamp::End;
    let check_degree = |d: usize| -> Result<(), PipelineError> {
        if d > settings.max_degree {
            return Err(PipelineError::new(
                ErrorKind::Limit,
                "limit.degree",
                format!(
                    "the result would have degree {d}, above the limit of {}",
                    settings.max_degree
                ),
                Location::default(),
            ));
        }
        Ok(())
    };
    let direction = op.direction();
    let (u, v) = (
        matches!(direction, Direction::U | Direction::Both),
        matches!(direction, Direction::V | Direction::Both),
    );
    let one = |g: Geometry| Ok((vec![g], None));
    let curve = |c: crate::nurbs::NurbsCurve| Ok((vec![Geometry::Curve(c)], None));
    let surface = |s: crate::nurbs::NurbsSurface| Ok((vec![Geometry::Surface(s)], None));
    match (g, op) {
        (_, &Operation::Elevate { by, .. }) if by == 0 || by > settings.max_elevate_by => {
            Err(PipelineError::new(
                if by == 0 {
                    ErrorKind::Usage
                } else {
                    ErrorKind::Limit
                },
                if by == 0 {
                    "elevate.zero"
                } else {
                    "limit.elevate_by"
                },
                format!("elevation by {by}: must be 1..={}", settings.max_elevate_by),
                Location::default(),
            ))
        }
        (Geometry::Curve(c), &Operation::Elevate { by, .. }) => {
            check_degree(c.degree() + by)?;
            curve(c.elevate_polling(by, &|| settings.cancel.is_set())?)
        }
        (Geometry::Surface(s), &Operation::Elevate { by, .. }) => {
            let stop = || settings.cancel.is_set();
            let mut s = s.clone();
            if u {
                check_degree(s.degree_u() + by)?;
                s = s.elevate_u_polling(by, &stop)?;
            }
            if v {
                check_degree(s.degree_v() + by)?;
                s = s.elevate_v_polling(by, &stop)?;
            }
            surface(s)
        }
        (Geometry::Curve(c), Operation::Clamp { .. }) => curve(c.clamp()?),
        (Geometry::Curve(c), Operation::Unclamp { .. }) => curve(c.unclamp()?),
        (Geometry::Surface(s), Operation::Clamp { .. } | Operation::Unclamp { .. }) => {
            let un = matches!(op, Operation::Unclamp { .. });
            let mut s = s.clone();
            if u {
                s = if un {
                    s.unclamp_u(End::Both)?
                } else {
                    s.clamp_u(End::Both)?
                };
            }
            if v {
                s = if un {
                    s.unclamp_v(End::Both)?
                } else {
                    s.clamp_v(End::Both)?
                };
            }
            surface(s)
        }
        (Geometry::Curve(c), &Operation::InsertKnot { u: t, times, .. }) => {
            check_knot_insertion(c.knots(), c.degree(), c.domain(), t, times, "")?;
            curve(c.insert_knot(t, times)?)
        }
        (Geometry::Surface(s), &Operation::InsertKnot { u: t, times, .. }) => match direction {
            Direction::U => {
                check_knot_insertion(s.knots_u(), s.degree_u(), s.domain().0, t, times, " in u")?;
                surface(s.insert_knot_u(t, times)?)
            }
            Direction::V => {
                check_knot_insertion(s.knots_v(), s.degree_v(), s.domain().1, t, times, " in v")?;
                surface(s.insert_knot_v(t, times)?)
            }
            Direction::Both => Err(needs_direction("insert_knot", "knot insertion")),
        },
        (Geometry::Curve(c), Operation::Refine { knots, .. }) => {
            check_refinement(c.knots(), c.degree(), c.domain(), knots, "")?;
            curve(c.refine(&sorted(knots))?)
        }
        (Geometry::Surface(s), Operation::Refine { knots, .. }) => match direction {
            Direction::U => {
                check_refinement(s.knots_u(), s.degree_u(), s.domain().0, knots, " in u")?;
                surface(s.refine_u(&sorted(knots))?)
            }
            Direction::V => {
                check_refinement(s.knots_v(), s.degree_v(), s.domain().1, knots, " in v")?;
                surface(s.refine_v(&sorted(knots))?)
            }
            Direction::Both => Err(needs_direction("refine", "knot refinement")),
        },
        (Geometry::Curve(c), Operation::Halve { .. }) => curve(c.halve()?),
        (Geometry::Surface(s), Operation::Halve { .. }) => match direction {
            Direction::U => surface(s.halve_u()?),
            Direction::V => surface(s.halve_v()?),
            Direction::Both => surface(s.halve_u()?.halve_v()?),
        },
        (Geometry::Curve(c), &Operation::Reduce { tolerance, .. }) => {
            let (r, bound) = c.reduce(tolerance)?;
            let message = format!(
                "degree {} -> {}, deviation at most {bound:e}",
                c.degree(),
                r.degree()
            );
            Ok((vec![Geometry::Curve(r)], Some((message, Some(bound)))))
        }
        (Geometry::Surface(s), &Operation::Reduce { tolerance, .. }) => {
            // The bounds of the two directions add up: the v reduction moves the already
            // u-reduced surface by at most its own bound.
            let mut r = s.clone();
            let mut bound = 0.0;
            let mut steps = Vec::new();
            if u {
                let (next, b) = r.reduce_u(tolerance)?;
                steps.push(format!("u {} -> {}", r.degree_u(), next.degree_u()));
                r = next;
                bound += b;
            }
            if v {
                let (next, b) = r.reduce_v(tolerance - bound)?;
                steps.push(format!("v {} -> {}", r.degree_v(), next.degree_v()));
                r = next;
                bound += b;
            }
            let message = format!("degree {}, deviation at most {bound:e}", steps.join(", "));
            Ok((vec![Geometry::Surface(r)], Some((message, Some(bound)))))
        }
        (Geometry::Curve(c), &Operation::RemoveKnots { tolerance }) => {
            let (r, n) = c.remove_all_removable(tolerance)?;
            let message = format!("removed {n} knot(s) within {tolerance:e}");
            Ok((vec![Geometry::Curve(r)], Some((message, Some(tolerance)))))
        }
        (Geometry::Surface(s), &Operation::RemoveKnots { tolerance }) => {
            let (r, n) = s.remove_all_removable(tolerance)?;
            let message = format!("removed {n} knot(s) within {tolerance:e}");
            Ok((vec![Geometry::Surface(r)], Some((message, Some(tolerance)))))
        }
        (Geometry::Curve(c), Operation::Decompose) => Ok((
            c.bezier_segments()?
                .into_iter()
                .map(Geometry::Curve)
                .collect(),
            None,
        )),
        (Geometry::Surface(s), Operation::Decompose) => {
            // u-major: patch (i, j) is entity i * nv + j + 1.
            let patches = s.bezier_patches()?.into_vec();
            Ok((patches.into_iter().map(Geometry::Surface).collect(), None))
        }
        (Geometry::Curve(c), &Operation::Split { at, .. }) => {
            let (a, b) = c.split_at(at)?;
            Ok((vec![Geometry::Curve(a), Geometry::Curve(b)], None))
        }
        (Geometry::Surface(s), &Operation::Split { at, .. }) => {
            let (a, b) = match direction {
                Direction::U => s.split_at_u(at)?,
                Direction::V => s.split_at_v(at)?,
                Direction::Both => return Err(needs_direction("split", "splitting")),
            };
            Ok((vec![Geometry::Surface(a), Geometry::Surface(b)], None))
        }
        (Geometry::Curve(c), Operation::Reverse { .. }) => curve(c.reverse()?),
        (Geometry::Surface(s), Operation::Reverse { .. }) => {
            let mut s = s.clone();
            if u {
                s = s.reverse_u()?;
            }
            if v {
                s = s.reverse_v()?;
            }
            surface(s)
        }
        (Geometry::Curve(c), &Operation::Reparameterize { start, end, .. }) => {
            curve(c.reparameterize(start, end)?)
        }
        (Geometry::Surface(s), &Operation::Reparameterize { start, end, .. }) => {
            let mut s = s.clone();
            if u {
                s = s.reparameterize_u(start, end)?;
            }
            if v {
                s = s.reparameterize_v(start, end)?;
            }
            surface(s)
        }
        (Geometry::Curve(c), Operation::Transform { matrix }) => curve(c.transform(matrix)?),
        (Geometry::Surface(s), Operation::Transform { matrix }) => surface(s.transform(matrix)?),
        (Geometry::Curve(_), Operation::Iso { .. }) => Err(PipelineError::usage(
            "iso.curve",
            "iso-curves are taken from surfaces; this entity is a curve",
        )),
        (Geometry::Surface(s), &Operation::Iso { at, .. }) => match direction {
            Direction::U => curve(s.iso_u(at)?),
            Direction::V => curve(s.iso_v(at)?),
            Direction::Both => Err(needs_direction("iso", "an iso-curve")),
        },
        (Geometry::Curve(c), &Operation::Periodic { tolerance, .. }) => {
            curve(c.to_periodic(tolerance)?)
        }
        (Geometry::Surface(s), &Operation::Periodic { tolerance, .. }) => {
            let mut s = s.clone();
            if u {
                s = s.to_periodic_u(tolerance)?;
            }
            if v {
                s = s.to_periodic_v(tolerance)?;
            }
            surface(s)
        }
        (Geometry::Curve(c), &Operation::DerivativeCurve { order }) => {
            curve(c.derivative_curve(order)?)
        }
        (Geometry::Surface(_), Operation::DerivativeCurve { .. }) => Err(PipelineError::usage(
            "derivative_curve.surface",
            "derivative curves are taken from curves; this entity is a surface",
        )),
        (_, Operation::Join { .. }) => one(g.clone()),
    }
}

/// The usage error of an operation on a surface that needs one direction (u or v).
fn needs_direction(code: &str, what: &str) -> PipelineError {
    PipelineError::usage(
        &format!("{code}.direction"),
        format!("{what} on a surface needs a direction (u or v)"),
    )
}

/// The knots in ascending order (A5.4 wants them sorted).
fn sorted(knots: &[f64]) -> Vec<f64> {
    let mut x = knots.to_vec();
    x.sort_by(f64::total_cmp);
    x
}

/// Checks a knot refinement as [`check_knot_insertion`] checks each of its knots (the
/// multiplicity counts the knots already there and every copy in the list).
fn check_refinement(
    knots: &[f64],
    degree: usize,
    domain: (f64, f64),
    x: &[f64],
    which: &str,
) -> Result<(), PipelineError> {
    if x.is_empty() {
        return Err(PipelineError::usage(
            "refine.empty",
            "knot refinement needs at least one knot",
        ));
    }
    for (distinct, times) in crate::nurbs::knots::runs(&sorted(x)).map(|(_, t, m)| (t, m)) {
        check_knot_insertion(knots, degree, domain, distinct, times, which)?;
    }
    Ok(())
}

/// Checks a knot insertion in the user's terms before the algorithm (NURBS Book A5.1) runs:
/// the knot must lie in the domain (`insert_knot.domain`) and its multiplicity may not exceed
/// the degree (`insert_knot.multiplicity`). Both are usage errors, as a parameter outside the
/// domain is for `evaluate`. `which` names the surface direction (`" in u"`), empty for curves.
fn check_knot_insertion(
    knots: &[f64],
    degree: usize,
    (start, end): (f64, f64),
    t: f64,
    times: usize,
    which: &str,
) -> Result<(), PipelineError> {
    if !(t >= start && t <= end) {
        return Err(PipelineError::usage(
            "insert_knot.domain",
            format!("knot {t} is outside the domain [{start}, {end}]{which}"),
        ));
    }
    let s = knots.iter().filter(|&&k| k == t).count();
    let total = s.saturating_add(times);
    if total > degree {
        let hint = match (t == start || t == end, s > degree) {
            (true, true) => "; that end is already clamped",
            (true, false) => {
                "; at a domain end, `nurbsx clamp` raises the multiplicity to degree + 1 \
                 without changing the shape"
            }
            _ => "",
        };
        return Err(PipelineError::usage(
            "insert_knot.multiplicity",
            format!(
                "knot {t}{which} already appears {s} time(s); inserting it {times} more \
                 time(s) would make {total}, above the degree {degree}{hint}"
            ),
        ));
    }
    Ok(())
}

/// Moves a parameter that lies within a few units in the last place of a domain end onto
/// that end (an end computed as `a + (b - a) * 1.0` may miss `b` by one ulp); parameters
/// further out are left for the evaluator to refuse.
fn snap_to_domain(t: f64, (start, end): (f64, f64)) -> f64 {
    let slack = 4.0 * f64::EPSILON * start.abs().max(end.abs());
    if t < start && start - t <= slack {
        start
    } else if t > end && t - end <= slack {
        end
    } else {
        t
    }
}

/// Reply bytes per curve point at most: an OBJ `v` line and its index in the `l` line (SVG
/// takes less).
const CURVE_POINT_BYTES: f64 = 3.0 * NUMBER_BYTES + 16.0;

/// Reply bytes per surface vertex at most: its `v` and `vn` lines and its share (two
/// triangles) of the `f` lines.
const SURFACE_VERTEX_BYTES: f64 = 6.0 * NUMBER_BYTES + 8.0 + 2.0 * 72.0;

/// Tessellates one entity (or all with `entity = None`) under a chord tolerance (curves by
/// the osculating-circle rule, surfaces to crack-free grids welded at seams and poles), to
/// be written ([`Tessellated::write`]) as OBJ, binary STL, binary glTF 2.0 or an SVG or
/// PNG picture ([`super::mesh`], [`super::picture`]). What the format cannot hold is left
/// out as [`super::mesh::plan`] says (call it first to report the warnings).
///
/// Before any mesh is built, the vertex count is estimated for every entity
/// ([`crate::nurbs::NurbsCurve::tessellation_estimate`]) and the request refused when the
/// sum exceeds [`Settings::max_mesh_vertices`] or the working-memory budget
/// ([`super::mesh::vertex_cap`]), or its text would exceed [`Settings::max_reply_bytes`];
/// the same vertex cap bounds the work itself, and the stop signal is polled every
/// [`crate::nurbs::tessellate::STOP_POLL`] steps.
///
/// A document with faces is drawn as a part (see [`super::mesh`]): faces trimmed, edges as
/// lines, the free entities as before; faces that cannot be meshed are left out with a
/// warning in the mesh's diagnostics.
pub fn tessellate(
    doc: &Document,
    entity: Option<&str>,
    tolerance: f64,
    format: MeshFormat,
    settings: &Settings,
) -> Result<Tessellated, PipelineError> {
    use super::mesh;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(PipelineError::usage(
            "tessellate.tolerance",
            format!("tolerance must be a positive number, got {tolerance}"),
        ));
    }
    let plan = mesh::plan(doc, entity, format)?;
    // The a-priori estimate, before any mesh is built.
    let mut estimate = 0.0;
    let mut reply = 0.0;
    for e in &plan.entities {
        settings.cancel.check()?;
        let (n, bytes) = match &e.geometry {
            Geometry::Curve(c) => (c.tessellation_estimate(tolerance), CURVE_POINT_BYTES),
            Geometry::Surface(s) => (s.tessellation_estimate(tolerance), SURFACE_VERTEX_BYTES),
        };
        estimate += n;
        reply += n * bytes;
    }
    if let Some(topology) = plan.topology {
        let model = &topology.model;
        for f in &plan.faces {
            settings.cancel.check()?;
            if let Some(face) = model.faces.get(f.0) {
                let n = face.surface.tessellation_estimate(tolerance);
                estimate += n;
                reply += n * SURFACE_VERTEX_BYTES;
            }
        }
        for &e in &plan.edges {
            settings.cancel.check()?;
            if let Some(edge) = model.edges.get(e) {
                let n = edge.curve.tessellation_estimate(tolerance);
                estimate += n;
                reply += n * CURVE_POINT_BYTES;
            }
        }
    }
    if estimate > settings.max_mesh_vertices as f64 {
        return Err(PipelineError::new(
            ErrorKind::Limit,
            "limit.mesh_vertices",
            format!(
                "the tessellation would need about {estimate:.3e} vertices (estimated from the \
                 curvature before the work), above the limit of {} vertices; use a larger \
                 tolerance",
                settings.max_mesh_vertices
            ),
            Location::default(),
        ));
    }
    if estimate > mesh::vertex_cap(settings) as f64 {
        return Err(mesh::over_the_cap(
            &format!("the tessellation (about {estimate:.3e} vertices, estimated before the work)"),
            settings,
        ));
    }
    check_reply(
        reply,
        "mesh text",
        "use a larger tolerance or fewer entities",
        settings,
    )?;
    Ok(Tessellated {
        mesh: mesh::tessellate_all(&plan, tolerance, settings)?,
        format,
        units: doc.units.short_name(),
    })
}

/// A tessellation ready to be written: [`tessellate`]'s mesh, the format and the unit
/// (for pictures).
#[derive(Debug)]
pub struct Tessellated {
    /// The meshes and what the meshing noticed.
    pub mesh: super::mesh::Tessellation,
    format: MeshFormat,
    units: &'static str,
}

impl Tessellated {
    /// Writes the file into `out`, after checking its exact size against
    /// [`Settings::max_reply_bytes`]. OBJ, STL and glTF are written as they are formatted
    /// (so a streamed reply never holds the whole file; OBJ's size is counted by a
    /// formatting pass that keeps nothing, glTF's from its layout: its JSON chunk and the
    /// mesh counts); the pictures are built whole first. A failed write means the reader
    /// went away: the error is [`super::cancelled`].
    pub fn write(
        &self,
        out: &mut dyn std::io::Write,
        settings: &Settings,
    ) -> Result<(), PipelineError> {
        use super::{mesh, picture};
        let (faces, curves) = (&self.mesh.faces, &self.mesh.curves);
        let glb = matches!(self.format, MeshFormat::Glb).then(|| mesh::Glb::layout(faces, curves));
        let advice = "use a larger tolerance or fewer entities";
        let over = || {
            PipelineError::new(
                ErrorKind::Limit,
                "limit.reply_bytes",
                format!(
                    "the picture passed the reply limit of {} bytes while it was drawn; {advice}",
                    settings.max_reply_bytes
                ),
                Location::default(),
            )
        };
        let whole = match self.format {
            MeshFormat::Obj | MeshFormat::Stl | MeshFormat::Glb => None,
            MeshFormat::Svg => {
                // At least SVG_TRIANGLE_BYTES a triangle: refused before it is drawn.
                let triangles: usize = faces.iter().map(|f| f.triangles.len()).sum();
                check_reply(
                    (triangles as f64) * picture::SVG_TRIANGLE_BYTES as f64,
                    "picture",
                    advice,
                    settings,
                )?;
                let svg = picture::svg(faces, curves, self.units, settings.max_reply_bytes);
                Some(svg.ok_or_else(over)?.into_bytes())
            }
            // The SVG drawn for the raster is not the reply: only the PNG is checked.
            MeshFormat::Png => {
                let svg = picture::svg(faces, curves, self.units, usize::MAX).ok_or_else(over)?;
                Some(picture::png(&svg)?)
            }
        };
        let size = match (&whole, &glb, self.format) {
            (Some(bytes), _, _) => bytes.len(),
            (None, Some(glb), _) => glb.size(),
            (None, None, MeshFormat::Stl) => mesh::stl_bytes(faces),
            (None, None, _) => {
                let mut counted = ByteCount(0);
                mesh::write_obj(&mut counted, faces, curves).map_err(|_| super::cancelled())?;
                counted.0
            }
        };
        check_reply(size as f64, "mesh output", advice, settings)?;
        match (whole, glb, self.format) {
            (Some(bytes), _, _) => out.write_all(&bytes),
            (None, Some(glb), _) => glb.write(out, faces, curves),
            (None, None, MeshFormat::Stl) => mesh::write_stl(out, faces),
            (None, None, _) => mesh::write_obj(out, faces, curves),
        }
        .map_err(|_| super::cancelled())
    }
}

/// An `io::Write` that keeps only the number of bytes written.
struct ByteCount(usize);

impl std::io::Write for ByteCount {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0 += bytes.len();
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// [`tessellate`] and [`Tessellated::write`] into memory: the file and the meshing's
/// warnings.
pub fn tessellate_file(
    doc: &Document,
    entity: Option<&str>,
    tolerance: f64,
    format: MeshFormat,
    settings: &Settings,
) -> Result<MeshFile, PipelineError> {
    let tessellated = tessellate(doc, entity, tolerance, format, settings)?;
    let mut bytes = Vec::new();
    tessellated.write(&mut bytes, settings)?;
    Ok(MeshFile {
        bytes,
        diagnostics: tessellated.mesh.diagnostics,
    })
}

/// A written mesh file and what the meshing noticed (faces left out, triangles above the
/// tolerance); the plan's own warnings come from [`super::mesh::plan`].
#[derive(Debug, Clone)]
pub struct MeshFile {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// Warnings of the meshing.
    pub diagnostics: Vec<Diagnostic>,
}

/// The affine matrix of `scale`, then a rotation by `degrees` about the axis `axis`
/// through the origin (Rodrigues' formula, right-handed), then `translate`; each optional.
/// Errors: a zero or non-finite axis, non-finite numbers.
pub fn affine(
    scale: Option<f64>,
    rotate: Option<(Point3, f64)>,
    translate: Option<Point3>,
) -> Result<crate::nurbs::transform::Affine, PipelineError> {
    let s = scale.unwrap_or(1.0);
    let mut r = [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]];
    if let Some((axis, degrees)) = rotate {
        let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        if !(len.is_finite() && len > 0.0 && degrees.is_finite()) {
            return Err(PipelineError::usage(
                "transform.rotate",
                "the rotation needs a non-zero finite axis and a finite angle",
            ));
        }
        let k = axis.map(|a| a / len);
        let (sin, cos) = degrees.to_radians().sin_cos();
        // R = cos I + sin [k]x + (1 - cos) k k^T
        let rot: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let cross = match (i, j) {
                    (0, 1) => -k[2],
                    (0, 2) => k[1],
                    (1, 0) => k[2],
                    (1, 2) => -k[0],
                    (2, 0) => -k[1],
                    (2, 1) => k[0],
                    _ => 0.0,
                };
                let id = if i == j { cos } else { 0.0 };
                id + sin * cross + (1.0 - cos) * k[i] * k[j]
            })
        });
        r = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|m| rot[i][m] * r[m][j]).sum())
        });
    }
    let t = translate.unwrap_or([0.0; 3]);
    let m: crate::nurbs::transform::Affine =
        std::array::from_fn(|i| [r[i][0], r[i][1], r[i][2], t[i]]);
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Err(PipelineError::usage(
            "transform.matrix",
            "the transform's entries must be finite",
        ));
    }
    Ok(m)
}
