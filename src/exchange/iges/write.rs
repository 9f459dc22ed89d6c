//! [`Document`] -> IGES 5.3 text: the topology (faces as 144/142, or 186 B-rep solids, by
//! [`super::write_topology`]), then 126/128 with PROP flags computed from the data
//! (spec.md a.2, a.4, b.1, b.2; pitfalls.md A4, B11, D21).
//!
//! - PROP1 (126): planar when every pole lies in one plane (2-D curves: the xy plane);
//!   the written normal is the document's `Meta::plane_normal` when the poles lie in that
//!   plane, else the computed unit normal with `z >= 0`. Collinear poles: 0 (no unique plane).
//! - PROP2: closed when the curve's ends (surface: the boundary curves) coincide.
//! - PROP3: 1 (polynomial, weights written as 1.0) when the model has no weights, 0 when it
//!   has weights, even all equal: the model's rational flag is what the source file said, and
//!   keeping it makes IGES read -> write -> read bit-identical (an all-equal-weights rational
//!   curve written as PROP3 = 1 would read back without weights). pitfalls.md 11: PROP3 = 1
//!   only when the weights are equal, which this satisfies.
//! - PROP4/PROP5: 1 only when the knots and poles have the periodic layout.
//! - `V(0), V(1)` (`U(0)..V(1)`): the entity's declared parameter range, clipped to the knot
//!   domain (IGES 5.3 sections 4.23, 4.24 require it inside); the domain when the entity
//!   declares none or the clipped range is empty ([`written_range`]; [`range_warnings`]
//!   reports every range the writer changes beyond rounding).
//! - DE status `00000000`, or `00000500` (use flag 05, 2-D parametric) for 2-D curves; the
//!   form number of the entity's kind (`Meta::shape`: 126 forms 1-5, 128 forms 1-8) when the
//!   geometry passes that kind's check ([`forms`]), else 0 ([`form_warnings`](super::form_warnings)
//!   reports the entities that fail).
//! - Global: units flag and name of the unit the numbers are in (poles are scaled once when
//!   `ExportOptions::units` differs from the document's unit), resolution, maximum
//!   coordinate, dates from `ExportOptions::timestamp` (deterministic when given).

use nurbsx_parsers::iges::records::{Curve126, Surface128};
use nurbsx_parsers::iges::writer::{self, WriteParams};
use nurbsx_parsers::iges::{DirectoryEntry, Global, Status};
use nurbsx_parsers::real::NonFiniteReal;

use std::borrow::Cow;

use super::{analysis, forms};
use crate::exchange::{Diagnostic, Document, ExportOptions, Location, Meta, ParameterRange};
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3};

/// Writes the document as an IGES 5.3 file: its topology when it has one (faces as 144
/// trimmed surfaces with 142 boundaries, or with `ExportOptions::iges_brep` solids and
/// shells as 186 with 514/510/508/504/502; the `write_topology` module), then every curve and
/// surface that no face or edge names, as 126/128.
///
/// Errors (a `Diagnostic` with code `iges.write` or `options.timestamp`) only for values
/// that cannot be written (non-finite after unit scaling) or a malformed timestamp.
///
/// Each entity becomes its typed record ([`Curve126`], [`Surface128`], the topology
/// records) when the writer reaches it, and the record writes itself into the P section
/// ([`writer::write_with`]).
pub fn write(document: &Document, options: &ExportOptions) -> Result<String, Diagnostic> {
    let unit = options.units.unwrap_or(document.units);
    let factor = (unit != document.units).then(|| document.units.to_mm() / unit.to_mm());
    let mut items = Items::new(factor, document.entities.len());
    let named = if document.topology.is_empty() {
        std::collections::HashSet::new()
    } else {
        super::write_topology::write(document, options.iges_brep, &options.cancel, &mut items)
    };
    for e in &document.entities {
        // Stopped: the rest is skipped (`exchange::write` discards the text).
        if options.cancel.is_set() {
            break;
        }
        // A face's surface or an edge's curve is written with its face; a 2-D curve that a
        // 142 or 508 used is a pcurve, which the topology carries on its coedge.
        let pcurve = !named.is_empty()
            && !e.meta.used_by.is_empty()
            && matches!(&e.geometry, Geometry::Curve(c) if c.dimension() == 2);
        if named.contains(e.id.as_str()) || pcurve {
            continue;
        }
        match &e.geometry {
            Geometry::Curve(c) => items.curve(Cow::Borrowed(c), &e.meta, 0),
            Geometry::Surface(s) => items.surface(Cow::Borrowed(s), &e.meta, 0),
        };
    }
    let tolerance = document.topology.model.max_tolerance() * factor.unwrap_or(1.0);
    let (start, global) = header(options, unit, items.max_coord, tolerance, items.des.len())?;
    // About 20 bytes a real with its delimiter, 64 of each 81 columns holding data.
    let p_bytes = items.reals.saturating_mul(28) + items.des.len() * 100;
    writer::write_with(
        &start,
        &global,
        &items.des,
        p_bytes,
        |index, w| match items.items.get(index) {
            // Stopped: end the write here (`exchange::write` replaces this error with
            // `cancelled`).
            _ if options.cancel.is_set() => Err(NonFiniteReal(f64::NAN)),
            Some(Item::Curve(c, p)) => curve_record(c, p, factor).write_params(w),
            Some(Item::Surface(s, p)) => surface_record(s, p, factor).write_params(w),
            Some(Item::Record(r)) => r.write_params(w),
            None => Ok(()),
        },
    )
    .map_err(|e| Diagnostic::error("iges.write", e.to_string(), Location::default()))
}

/// One entity to write: a curve or surface with its computed flags, or a record that
/// writes itself (the topology's, whose pointers are already known).
pub(super) enum Item<'d> {
    Curve(Cow<'d, NurbsCurve>, CurvePlan),
    Surface(Cow<'d, NurbsSurface>, SurfacePlan),
    Record(Box<dyn WriteParams + 'd>),
}

/// The entities of the file in writing order, with their Directory Entries; the DE
/// pointer of each is known when it is added ([`writer::pointer_of`]), so the records
/// that name it can follow.
pub(super) struct Items<'d> {
    des: Vec<DirectoryEntry>,
    items: Vec<Item<'d>>,
    factor: Option<f64>,
    max_coord: f64,
    reals: usize,
}

impl<'d> Items<'d> {
    fn new(factor: Option<f64>, capacity: usize) -> Self {
        Items {
            des: Vec::with_capacity(capacity),
            items: Vec::with_capacity(capacity),
            factor,
            max_coord: 0.0,
            reals: 0,
        }
    }

    /// The unit factor the poles are scaled by when written.
    pub(super) fn factor(&self) -> Option<f64> {
        self.factor
    }

    fn push(&mut self, de: DirectoryEntry, item: Item<'d>) -> i64 {
        let pointer = writer::pointer_of(self.items.len());
        self.des.push(de);
        self.items.push(item);
        i64::try_from(pointer).unwrap_or(i64::MAX)
    }

    /// A 126 (2-D curves with use flag 05); `subordinate` is DE status digits 3-4 (1 for a
    /// curve another entity uses). Returns its DE pointer.
    pub(super) fn curve(&mut self, c: Cow<'d, NurbsCurve>, meta: &Meta, subordinate: u8) -> i64 {
        let use_flag = if c.dimension() == 2 { 5 } else { 0 };
        let mut d = de(
            126,
            meta,
            use_flag,
            forms::curve_form(&c, meta.shape, meta.shape_tolerance.unwrap_or(0.0)).unwrap_or(0),
        );
        d.status.subordinate = subordinate;
        let factor = self.factor;
        self.max_coord = c
            .control_points()
            .iter()
            .fold(self.max_coord, |m, &p| max_abs_point(m, scaled(p, factor)));
        self.reals += c.knots().len() + 4 * c.num_poles() + 5;
        let plan = curve_plan(&c, meta);
        self.push(d, Item::Curve(c, plan))
    }

    /// A 128; `subordinate` as for [`Items::curve`]. Returns its DE pointer.
    pub(super) fn surface(
        &mut self,
        s: Cow<'d, NurbsSurface>,
        meta: &Meta,
        subordinate: u8,
    ) -> i64 {
        let mut d = de(
            128,
            meta,
            0,
            forms::surface_form(&s, meta.shape, meta.shape_tolerance.unwrap_or(0.0)).unwrap_or(0),
        );
        d.status.subordinate = subordinate;
        let net = s.control_points().as_slice();
        let factor = self.factor;
        self.max_coord = net
            .iter()
            .fold(self.max_coord, |m, &p| max_abs_point(m, scaled(p, factor)));
        self.reals += s.knots_u().len() + s.knots_v().len() + 4 * net.len() + 4;
        let plan = surface_plan(&s, meta);
        self.push(d, Item::Surface(s, plan))
    }

    /// A topology record of type `entity_type` and form `form`, with DE status
    /// `subordinate` and `use_flag` (IGES 5.3 section 2.2.4.4.9). Returns its DE pointer.
    pub(super) fn record(
        &mut self,
        entity_type: i64,
        form: i64,
        subordinate: u8,
        use_flag: u8,
        record: impl WriteParams + 'd,
    ) -> i64 {
        let d = DirectoryEntry {
            entity_type,
            form,
            status: Status {
                subordinate,
                use_flag,
                ..Status::default()
            },
            ..DirectoryEntry::default()
        };
        self.push(d, Item::Record(Box::new(record)))
    }
}

/// The Start section text and the Global section of a file of `count` entities.
fn header(
    options: &ExportOptions,
    unit: crate::exchange::LengthUnit,
    max_coord: f64,
    tolerance: f64,
    count: usize,
) -> Result<(String, Global), Diagnostic> {
    let date = iges_date(options.timestamp.as_deref())?;
    let version = env!("CARGO_PKG_VERSION");
    let global = Global {
        param_delimiter: ',',
        record_delimiter: ';',
        product_id_sender: Some(options.file_name.clone()),
        file_name: Some(options.file_name.clone()),
        native_system_id: Some(format!("nurbsx {version}")),
        preprocessor_version: Some(format!("nurbsx {version}")),
        integer_bits: Some(32),
        single_max_power: Some(38),
        single_digits: Some(6),
        double_max_power: Some(308),
        double_digits: Some(15),
        product_id_receiver: Some(options.file_name.clone()),
        model_scale: Some(1.0),
        units_flag: Some(unit.iges_flag()),
        units_name: Some(unit.iges_name().to_owned()),
        line_weight_gradations: Some(1),
        max_line_width: Some(0.01),
        date: Some(date.clone()),
        // 1e-7 mm expressed in the file's unit (well below any modelling tolerance), or
        // the model's own tolerance when larger (a part sewn within a user's tolerance),
        // so that a reader joins what the model joins (Global parameter 19, IGES 5.3
        // section 2.2.4.3).
        resolution: Some((1e-7 / unit.to_mm()).max(tolerance)),
        max_coordinate: Some(max_coord),
        author: None,
        organization: None,
        version_flag: Some(11),
        drafting_standard: Some(0),
        modified_date: Some(date),
        application_protocol: None,
    };
    let start = format!("nurbsx {version}: exact NURBS exchange; {count} entities");
    Ok((start, global))
}

/// The 126 flags, parameter range and normal (module documentation).
pub(super) struct CurvePlan {
    planar: i64,
    closed: i64,
    polynomial: i64,
    periodic: i64,
    range: (f64, f64),
    normal: Point3,
}

/// The 128 flags and parameter range (module documentation).
pub(super) struct SurfacePlan {
    closed: [i64; 2],
    polynomial: i64,
    periodic: [i64; 2],
    range: [f64; 4],
}

fn curve_plan(c: &NurbsCurve, meta: &Meta) -> CurvePlan {
    let tol = analysis::tolerance(c.control_points().iter());
    let normal = if c.dimension() == 2 {
        Some([0.0, 0.0, 1.0])
    } else {
        match meta.plane_normal.as_deref().copied() {
            Some(n) if analysis::on_plane(c.control_points(), n, tol) && is_unit(n) => Some(n),
            _ => analysis::plane_normal(c.control_points(), tol),
        }
    };
    let range = written_range(meta.parameter_range.as_deref().map(|r| r.u), c.domain());
    CurvePlan {
        planar: i64::from(normal.is_some()),
        closed: i64::from(analysis::curve_closed(c, tol)),
        polynomial: i64::from(c.weights().is_none()),
        periodic: i64::from(analysis::curve_periodic(c, tol)),
        range,
        normal: normal.unwrap_or([0.0, 0.0, 0.0]),
    }
}

fn surface_plan(s: &NurbsSurface, meta: &Meta) -> SurfacePlan {
    let net = s.control_points();
    let tol = analysis::tolerance(net.as_slice().iter());
    let (du, dv) = s.domain();
    let ru = written_range(meta.parameter_range.as_deref().map(|r| r.u), du);
    let rv = written_range(meta.parameter_range.as_deref().and_then(|r| r.v), dv);
    SurfacePlan {
        closed: [
            i64::from(analysis::surface_closed(s, 0, tol)),
            i64::from(analysis::surface_closed(s, 1, tol)),
        ],
        polynomial: i64::from(s.weights().is_none()),
        periodic: [
            i64::from(analysis::surface_periodic(s, 0, tol)),
            i64::from(analysis::surface_periodic(s, 1, tol)),
        ],
        range: [ru.0, ru.1, rv.0, rv.1],
    }
}

/// The 126 record of a curve (IGES 5.3 section 4.23): poles scaled, weights 1.0 when the
/// curve is polynomial.
fn curve_record(c: &NurbsCurve, p: &CurvePlan, factor: Option<f64>) -> Curve126 {
    let n = c.num_poles();
    Curve126 {
        degree: c.degree(),
        planar: p.planar,
        closed: p.closed,
        polynomial: p.polynomial,
        periodic: p.periodic,
        knots: c.knots().to_vec(),
        weights: c.weights().map_or_else(|| vec![1.0; n], <[f64]>::to_vec),
        points: c
            .control_points()
            .iter()
            .map(|&q| scaled(q, factor))
            .collect(),
        v0: Some(p.range.0),
        v1: Some(p.range.1),
        normal: Some(p.normal),
        extra: 0,
    }
}

/// The 128 record of a surface (IGES 5.3 section 4.24): weights and poles listed with the
/// first (u) index fastest, poles scaled.
fn surface_record(s: &NurbsSurface, p: &SurfacePlan, factor: Option<f64>) -> Surface128 {
    let net = s.control_points();
    let (nu, nv) = (net.nu(), net.nv());
    let mut points = Vec::with_capacity(nu * nv);
    let mut weights = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            points.push(scaled(*net.get(i, j), factor));
            weights.push(s.weight(i, j));
        }
    }
    Surface128 {
        degree: [s.degree_u(), s.degree_v()],
        poles: [nu, nv],
        closed: p.closed,
        polynomial: p.polynomial,
        periodic: p.periodic,
        knots_u: s.knots_u().to_vec(),
        knots_v: s.knots_v().to_vec(),
        weights,
        points,
        range: Some(p.range),
        extra: 0,
    }
}

/// `m` and the largest coordinate magnitude of `p`.
fn max_abs_point(m: f64, p: Point3) -> f64 {
    p.iter().fold(m, |m, &x| m.max(x.abs()))
}

fn scaled(p: Point3, factor: Option<f64>) -> Point3 {
    match factor {
        Some(f) => [p[0] * f, p[1] * f, p[2] * f],
        None => p,
    }
}

/// The Directory Entry: type, use flag, label, and the form number of the entity's kind
/// when its geometry passes the kind's check ([`forms::form`]; form 0 otherwise).
fn de(entity_type: i64, meta: &Meta, use_flag: u8, form: i64) -> DirectoryEntry {
    let label = meta
        .name
        .as_deref()
        .unwrap_or("")
        .chars()
        .filter(|c| c.is_ascii_graphic())
        .take(8)
        .collect();
    DirectoryEntry {
        entity_type,
        status: Status {
            use_flag,
            ..Status::default()
        },
        label,
        form,
        ..DirectoryEntry::default()
    }
}

/// The parameter range a 126 (`V(0), V(1)`) or one direction of a 128 declares: `range`
/// clipped to the knot `domain`, as IGES 5.3 sections 4.23 and 4.24 want it inside; the
/// domain when there is no range or nothing of it is left. A range computed in the model
/// (an edge's, a boundary segment's) lies in its curve's domain or beyond it by rounding
/// only, which the clip removes; a source file's range beyond it is reported by
/// [`range_warnings`].
pub(super) fn written_range(range: Option<(f64, f64)>, domain: (f64, f64)) -> (f64, f64) {
    match range {
        Some((a, b)) => {
            let clipped = (a.max(domain.0), b.min(domain.1));
            if clipped.0 < clipped.1 {
                clipped
            } else {
                domain
            }
        }
        None => domain,
    }
}

/// One warning per entity whose declared parameter range ([`Meta::parameter_range`], an
/// IGES file's `V(0), V(1)` or `U(0)..V(1)`) the IGES writer changes by more than rounding
/// (it writes the range clipped to the knot domain, or the domain when nothing of the range
/// is left in it): the file said a range outside the knot domain (its reader warned
/// `param_range_outside`), and the written file declares another.
pub fn range_warnings(document: &Document) -> Vec<Diagnostic> {
    document
        .entities
        .iter()
        .filter_map(|e| {
            let declared = *e.meta.parameter_range.as_deref()?;
            let (pairs, name) = match &e.geometry {
                Geometry::Curve(c) => (vec![(Some(declared.u), c.domain())], "V(0), V(1)"),
                Geometry::Surface(s) => {
                    let (du, dv) = s.domain();
                    (
                        vec![(Some(declared.u), du), (declared.v, dv)],
                        "U(0), U(1), V(0), V(1)",
                    )
                }
            };
            let written: Vec<(f64, f64)> = pairs
                .iter()
                .map(|&(r, d)| written_range(r, d))
                .collect();
            let changed = pairs.iter().zip(&written).any(|(&(r, d), &w)| {
                r.is_some_and(|r| !ParameterRange::same_within_rounding(r, w, d))
            });
            if !changed {
                return None;
            }
            let list = |rs: &mut dyn Iterator<Item = (f64, f64)>| {
                rs.flat_map(|(a, b)| [a, b])
                    .map(|x| x.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let declared_list = list(&mut pairs.iter().filter_map(|&(r, _)| r));
            let written_list = list(&mut written.iter().copied());
            Some(Diagnostic::warning(
                "range_clipped",
                format!(
                    "{name} = {declared_list} is not inside the knot domain; written as {written_list} (IGES 5.3 requires the range inside the domain)"
                ),
                Location::at_entity(e.id.clone()),
            ))
        })
        .collect()
}

fn is_unit(n: Point3) -> bool {
    ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() <= 1e-12
}

/// `YYYYMMDD.HHNNSS` from an ISO 8601 `YYYY-MM-DDTHH:MM:SS` time stamp, or the current UTC
/// time.
fn iges_date(timestamp: Option<&str>) -> Result<String, Diagnostic> {
    let digits: String = match timestamp {
        Some(t) => {
            let d: String = t.chars().filter(char::is_ascii_digit).collect();
            if d.len() < 14 {
                return Err(Diagnostic::error(
                    "options.timestamp",
                    format!("time stamp {t:?} is not YYYY-MM-DDTHH:MM:SS"),
                    Location::default(),
                ));
            }
            d
        }
        None => now_digits(),
    };
    Ok(format!("{}.{}", &digits[..8], &digits[8..14]))
}

/// The current UTC time as `YYYYMMDDHHMMSS` (days-to-civil conversion, H. Hinnant's
/// algorithm).
fn now_digits() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}{m:02}{d:02}{:02}{:02}{:02}",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}
