//! Measuring and comparing geometry: closest points (NURBS Book section 6.1,
//! `crate::nurbs::project`), curve lengths and surface areas to a tolerance, and the
//! Hausdorff distance between the geometry of two documents (`crate::nurbs::measure`).

use serde::Serialize;

use super::{ErrorKind, PipelineError, Settings, select};
use crate::exchange::{Document, Entity, Location};
use crate::nurbs::measure::{Shape, curve_length, directed_distance, surface_area};
use crate::nurbs::project::{invert_curve, invert_surface};
use crate::nurbs::{Geometry, Point3};

/// What `measure` computes.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasureRequest {
    /// Only this entity (default: every entity).
    pub entity: Option<String>,
    /// A point: the closest point of each entity to it is found too.
    pub closest: Option<Point3>,
    /// Tolerance of lengths (model units) and areas (model units squared).
    pub tolerance: f64,
}

/// A length or an area.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Quantity {
    /// The value.
    pub value: f64,
    /// The estimate of its error (the sum of `|Kronrod - Gauss|` over the pieces).
    pub error_estimate: f64,
    /// Whether the estimate reached the tolerance (else the piece limit was reached first).
    pub converged: bool,
    /// How many pieces (curves) or cells (surfaces) the domain was cut into.
    pub pieces: usize,
}

impl From<crate::nurbs::measure::Measured> for Quantity {
    fn from(m: crate::nurbs::measure::Measured) -> Self {
        Quantity {
            value: m.value,
            error_estimate: m.error,
            converged: m.converged,
            pieces: m.pieces,
        }
    }
}

/// The point of an entity closest to the requested point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosestPoint {
    /// Its parameters (`[u]` or `[u, v]`).
    pub parameters: Vec<f64>,
    /// The point (the entity's dimension).
    pub point: Vec<f64>,
    /// Its distance from the requested point.
    pub distance: f64,
}

/// What was measured on one entity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EntityMeasure {
    /// The entity's id.
    pub id: String,
    /// `curve` or `surface`.
    pub kind: &'static str,
    /// A curve's length.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length: Option<Quantity>,
    /// A surface's area.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area: Option<Quantity>,
    /// The closest point (with `closest`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closest: Option<ClosestPoint>,
}

/// The reply of `measure`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeasureReport {
    /// The tolerance asked for.
    pub tolerance: f64,
    /// One per entity measured.
    pub entities: Vec<EntityMeasure>,
    /// With `closest`: the id of the entity nearest to the point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nearest: Option<String>,
    /// Whether every length and area reached the tolerance.
    pub converged: bool,
}

/// An upper estimate of the reply bytes of one measured entity besides its id (which
/// appears up to twice: the entity and `nearest`).
const ENTITY_REPLY_BYTES: f64 = 400.0;

/// Measures the entities of `doc` (or the one `request.entity` names): every curve's
/// length, every surface's area, and with `closest` each one's closest point.
pub fn measure(
    doc: &Document,
    request: &MeasureRequest,
    settings: &Settings,
) -> Result<MeasureReport, PipelineError> {
    if !(request.tolerance.is_finite() && request.tolerance > 0.0) {
        return Err(PipelineError::usage(
            "measure.tolerance",
            format!(
                "the tolerance must be positive and finite, got {}",
                request.tolerance
            ),
        ));
    }
    if let Some(p) = request.closest
        && p.iter().any(|x| !x.is_finite())
    {
        return Err(PipelineError::usage(
            "measure.point",
            format!("the point must be finite, got {p:?}"),
        ));
    }
    let chosen: Vec<&Entity> = match &request.entity {
        Some(id) => vec![select(doc, Some(id))?],
        None => {
            // Errors the same way as an empty selection.
            select(doc, None)?;
            doc.entities.iter().collect()
        }
    };
    // A measured entity takes a few hundred bytes of reply.
    super::ops::check_reply(
        chosen
            .iter()
            .map(|e| ENTITY_REPLY_BYTES + 2.0 * e.id.len() as f64)
            .sum(),
        "measure reply",
        "measure fewer entities (entity)",
        settings,
    )?;
    let mut entities = Vec::with_capacity(chosen.len());
    for e in chosen {
        settings.cancel.check()?;
        let at = |err: crate::nurbs::GeometryError| {
            PipelineError::new(
                ErrorKind::Geometry,
                "geometry",
                err.to_string(),
                Location::at_entity(e.id.clone()),
            )
        };
        let dim = e.geometry.dimension();
        let m = match &e.geometry {
            Geometry::Curve(c) => EntityMeasure {
                id: e.id.to_string(),
                kind: "curve",
                length: Some(curve_length(c, request.tolerance).map_err(at)?.into()),
                area: None,
                closest: request
                    .closest
                    .map(|p| {
                        invert_curve(c, p)
                            .map(|(u, distance)| ClosestPoint {
                                parameters: vec![u],
                                point: c.point_at_unchecked(u)[..dim].to_vec(),
                                distance,
                            })
                            .ok_or_else(|| not_finite(&e.id))
                    })
                    .transpose()?,
            },
            Geometry::Surface(s) => EntityMeasure {
                id: e.id.to_string(),
                kind: "surface",
                length: None,
                area: Some(surface_area(s, request.tolerance).map_err(at)?.into()),
                closest: request
                    .closest
                    .map(|p| {
                        invert_surface(s, p, None)
                            .map(|i| ClosestPoint {
                                parameters: vec![i.u, i.v],
                                point: s.point_at_unchecked(i.u, i.v)[..dim].to_vec(),
                                distance: i.distance,
                            })
                            .ok_or_else(|| not_finite(&e.id))
                    })
                    .transpose()?,
            },
        };
        entities.push(m);
    }
    let nearest = entities
        .iter()
        .filter_map(|m| m.closest.as_ref().map(|c| (c.distance, &m.id)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, id)| id.clone());
    let converged = entities
        .iter()
        .flat_map(|m| m.length.iter().chain(&m.area))
        .all(|q| q.converged);
    Ok(MeasureReport {
        tolerance: request.tolerance,
        entities,
        nearest,
        converged,
    })
}

fn not_finite(id: &str) -> PipelineError {
    PipelineError::new(
        ErrorKind::Geometry,
        "measure.not_finite",
        format!("entity {id}: derivatives not finite near the closest point"),
        Location::at_entity(id.to_owned()),
    )
}

/// The farthest point of one side of a comparison from the other side.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Farthest {
    /// Its distance from the nearest entity of the other side.
    pub distance: f64,
    /// The entity it is on.
    pub entity: String,
    /// Its parameters there (`[u]` or `[u, v]`).
    pub parameters: Vec<f64>,
    /// The point.
    pub point: Point3,
    /// The nearest entity of the other side.
    pub nearest_entity: String,
    /// The nearest point's parameters there.
    pub nearest_parameters: Vec<f64>,
}

/// The reply of `compare`: the symmetric Hausdorff distance between two documents'
/// geometry, curves against curves and surfaces against surfaces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompareReport {
    /// The largest of the one-sided distances (model units of the first document).
    pub distance: f64,
    /// The first document's point farthest from the second document's geometry.
    pub first_to_second: Option<Farthest>,
    /// The second document's point farthest from the first document's geometry.
    pub second_to_first: Option<Farthest>,
    /// Curves of each document.
    pub curves: [usize; 2],
    /// Surfaces of each document.
    pub surfaces: [usize; 2],
}

/// The Hausdorff distance between the geometry of `a` and `b` (`b` in `a`'s unit, as the
/// caller loads it): each curve of one is sampled in every knot span and each sample
/// inverted onto the nearest curve of the other (`crate::nurbs::measure`), surfaces the
/// same; both directions. Independent of how either side is parameterised. Error: one
/// document has curves (or surfaces) and the other none, or neither has any geometry.
pub fn compare(
    a: &Document,
    b: &Document,
    settings: &Settings,
) -> Result<CompareReport, PipelineError> {
    let (ca, sa) = split(a);
    let (cb, sb) = split(b);
    let counts = |x: &[(usize, Shape<'_>)], y: &[(usize, Shape<'_>)], what: &str| {
        if x.is_empty() != y.is_empty() {
            Err(PipelineError::usage(
                "compare.kinds",
                format!(
                    "the first input has {} {what} and the second {}: nothing to compare them with",
                    x.len(),
                    y.len()
                ),
            ))
        } else {
            Ok(())
        }
    };
    counts(&ca, &cb, "curve(s)")?;
    counts(&sa, &sb, "surface(s)")?;
    if ca.is_empty() && sa.is_empty() {
        return Err(PipelineError::usage(
            "compare.empty",
            "neither input holds a curve or surface",
        ));
    }
    let stop = || settings.cancel.is_set();
    let one_side = |from: &[(usize, Shape<'_>)],
                    to: &[(usize, Shape<'_>)],
                    from_doc: &Document,
                    to_doc: &Document|
     -> Result<Option<Farthest>, PipelineError> {
        let f: Vec<Shape<'_>> = from.iter().map(|x| x.1).collect();
        let t: Vec<Shape<'_>> = to.iter().map(|x| x.1).collect();
        let found = directed_distance(&f, &t, &stop)?;
        settings.cancel.check()?;
        Ok(found.map(|w| farthest(&w, from, to, from_doc, to_doc)))
    };
    let worst = |x: Option<Farthest>, y: Option<Farthest>| match (x, y) {
        (Some(x), Some(y)) => Some(if y.distance > x.distance { y } else { x }),
        (x, y) => x.or(y),
    };
    let first_to_second = worst(one_side(&ca, &cb, a, b)?, one_side(&sa, &sb, a, b)?);
    let second_to_first = worst(one_side(&cb, &ca, b, a)?, one_side(&sb, &sa, b, a)?);
    let distance = first_to_second
        .iter()
        .chain(&second_to_first)
        .map(|f| f.distance)
        .fold(0.0, f64::max);
    Ok(CompareReport {
        distance,
        first_to_second,
        second_to_first,
        curves: [ca.len(), cb.len()],
        surfaces: [sa.len(), sb.len()],
    })
}

/// What `nurbsx compare --json` prints and `POST /v1/compare` replies: the comparison,
/// the tolerance verdict when a tolerance was given, the unit of the distances (the
/// first document's) and what reading both inputs reported.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompareSummary {
    /// The comparison.
    #[serde(flatten)]
    pub report: CompareReport,
    /// The tolerance asked for (model units of the first document).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Whether the distance is within it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub within_tolerance: Option<bool>,
    /// The length unit of the distances.
    pub units: &'static str,
    /// The diagnostics of reading the first, then the second input.
    pub diagnostics: Vec<crate::exchange::Diagnostic>,
}

/// The settings to read the second input of a comparison with: in the first document's
/// length unit, so that the distance is in one unit.
pub fn settings_for_second(settings: &Settings, first: &Document) -> Settings {
    let mut s = settings.clone();
    s.import.target_units = Some(first.units);
    s
}

/// [`compare`] with the verdict against `tolerance` and the reading `diagnostics` (the
/// caller's choice of them: the CLI shows those at its report level).
pub fn compare_summary(
    a: &Document,
    b: &Document,
    tolerance: Option<f64>,
    diagnostics: Vec<crate::exchange::Diagnostic>,
    settings: &Settings,
) -> Result<CompareSummary, PipelineError> {
    let report = compare(a, b, settings)?;
    Ok(CompareSummary {
        within_tolerance: tolerance.map(|t| report.distance <= t),
        report,
        tolerance,
        units: a.units.short_name(),
        diagnostics,
    })
}

/// The curves and the surfaces of a document, each with its entity index.
type Shapes<'a> = Vec<(usize, Shape<'a>)>;

fn split(d: &Document) -> (Shapes<'_>, Shapes<'_>) {
    let (mut curves, mut surfaces) = (Vec::new(), Vec::new());
    for (k, e) in d.entities.iter().enumerate() {
        match &e.geometry {
            Geometry::Curve(c) => curves.push((k, Shape::Curve(c))),
            Geometry::Surface(s) => surfaces.push((k, Shape::Surface(s))),
        }
    }
    (curves, surfaces)
}

fn farthest(
    w: &crate::nurbs::measure::Farthest,
    from: &[(usize, Shape<'_>)],
    to: &[(usize, Shape<'_>)],
    from_doc: &Document,
    to_doc: &Document,
) -> Farthest {
    let params = |s: Shape<'_>, (u, v): (f64, f64)| match s {
        Shape::Curve(_) => vec![u],
        Shape::Surface(_) => vec![u, v],
    };
    let (fi, fs) = from[w.from];
    let (ti, ts) = to[w.to];
    Farthest {
        distance: w.distance,
        entity: from_doc.entities[fi].id.to_string(),
        parameters: params(fs, w.at),
        point: w.point,
        nearest_entity: to_doc.entities[ti].id.to_string(),
        nearest_parameters: params(ts, w.nearest_at),
    }
}
