//! `make`: exact curves and surfaces built from their defining numbers, on top of the core's
//! constructions (`nurbs::conic`: A7.1 arcs with the fewest segments, lines; `nurbs::sweep`:
//! A8.1 revolution, extrusion, ruled surfaces and the ISO 10303-42 quadrics; `nurbs::coons`:
//! Coons patches). The entity's
//! `meta.shape` names what was built, so the STEP/IGES writers can record it.

use crate::exchange::{Document, Entity, Format, LengthUnit, Meta, Shape, Source};
use crate::nurbs::conic::{ConicKind, conic_arc, line_segment};
use crate::nurbs::sweep::{self, Frame};
use crate::nurbs::{Geometry, NurbsCurve, Point3};

use serde::Serialize;

use super::PipelineError;

/// What to build. Angles are in degrees; axes need not be unit vectors; `reference` (the
/// direction of angle 0) defaults to a direction perpendicular to the axis.
#[derive(Debug, Clone, PartialEq)]
pub enum MakeShape {
    /// A circular arc (a full circle for 0..360) about `normal` through `centre`.
    Arc {
        /// Centre.
        centre: Point3,
        /// Plane normal (rotation axis, right-handed).
        normal: Point3,
        /// Direction of angle 0.
        reference: Option<Point3>,
        /// Radius (> 0).
        radius: f64,
        /// Start angle (degrees).
        start: f64,
        /// End angle (degrees), `start < end <= start + 360`.
        end: f64,
    },
    /// An elliptic arc: semi-axis `major` along `reference`, `minor` across.
    Ellipse {
        /// Centre.
        centre: Point3,
        /// Plane normal.
        normal: Point3,
        /// Direction of the major semi-axis.
        reference: Option<Point3>,
        /// Semi-axis along `reference` (> 0).
        major: f64,
        /// The other semi-axis (> 0).
        minor: f64,
        /// Start angle (degrees, the ellipse's parameter).
        start: f64,
        /// End angle (degrees).
        end: f64,
    },
    /// The segment from `from` to `to` on [0, 1].
    Line {
        /// Start point.
        from: Point3,
        /// End point.
        to: Point3,
    },
    /// A right circular cylinder: radius, height along the axis, sweep angle.
    Cylinder {
        /// A point of the axis (the base centre).
        origin: Point3,
        /// Axis direction.
        axis: Point3,
        /// Direction of angle 0.
        reference: Option<Point3>,
        /// Radius (> 0).
        radius: f64,
        /// Height along the axis (> 0).
        height: f64,
        /// Sweep (degrees, 0 < sweep <= 360).
        sweep: f64,
    },
    /// A right circular cone: base radius, semi-angle (degrees), height along the axis.
    Cone {
        /// The base centre.
        origin: Point3,
        /// Axis direction.
        axis: Point3,
        /// Direction of angle 0.
        reference: Option<Point3>,
        /// Radius at the base (>= 0).
        radius: f64,
        /// Semi-angle (degrees, |a| < 90; negative narrows along the axis).
        semi_angle: f64,
        /// Height along the axis (> 0).
        height: f64,
        /// Sweep (degrees).
        sweep: f64,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        centre: Point3,
        /// Polar axis.
        axis: Point3,
        /// Direction of longitude 0.
        reference: Option<Point3>,
        /// Radius (> 0).
        radius: f64,
    },
    /// A torus.
    Torus {
        /// Centre.
        centre: Point3,
        /// Axis.
        axis: Point3,
        /// Direction of angle 0.
        reference: Option<Point3>,
        /// Distance from the axis to the tube's centre (> minor).
        major: f64,
        /// Tube radius (> 0).
        minor: f64,
    },
    /// A profile curve revolved about an axis (A8.1).
    Revolve {
        /// The profile.
        profile: NurbsCurve,
        /// A point of the axis.
        axis_point: Point3,
        /// Axis direction.
        axis: Point3,
        /// Sweep (degrees, 0 < angle <= 360).
        angle: f64,
    },
    /// A curve swept along a vector: `S(u, v) = C(u) + v d`, v in [0, 1].
    Extrude {
        /// The curve.
        curve: NurbsCurve,
        /// The sweep vector.
        direction: Point3,
    },
    /// The ruled surface between two curves (v = 0 on the first).
    Ruled {
        /// First rail.
        first: NurbsCurve,
        /// Second rail.
        second: NurbsCurve,
    },
    /// The bilinearly blended Coons patch of four polynomial boundaries, `[S(u,0), S(u,1),
    /// S(0,v), S(1,v)]`, whose corners meet within `tolerance`.
    Coons {
        /// The boundaries.
        boundaries: Box<[NurbsCurve; 4]>,
        /// Largest accepted corner gap.
        tolerance: f64,
    },
}

fn invalid(message: impl Into<String>) -> PipelineError {
    PipelineError::usage("make.arguments", message)
}

fn norm(a: Point3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn unit(a: Point3, what: &str) -> Result<Point3, PipelineError> {
    let n = norm(a);
    if !(n.is_finite() && n > 0.0) {
        return Err(invalid(format!(
            "the {what} must be a non-zero finite vector"
        )));
    }
    Ok(a.map(|c| c / n))
}

fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The right-handed orthonormal frame at `origin` with z along `axis` and x along the
/// part of `reference` perpendicular to it (default: the coordinate axis least aligned with
/// `axis`, made perpendicular), as ISO 10303-42 builds an axis2_placement_3d's axes.
pub fn frame(
    origin: Point3,
    axis: Point3,
    reference: Option<Point3>,
) -> Result<Frame, PipelineError> {
    if !origin.iter().all(|c| c.is_finite()) {
        return Err(invalid("the origin must be finite"));
    }
    let z = unit(axis, "axis")?;
    let r = match reference {
        Some(r) => r,
        None => {
            let k = (0..3)
                .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
                .unwrap_or(0);
            let mut e = [0.0; 3];
            e[k] = 1.0;
            e
        }
    };
    let along = r[0] * z[0] + r[1] * z[1] + r[2] * z[2];
    let x = unit(
        [
            r[0] - along * z[0],
            r[1] - along * z[1],
            r[2] - along * z[2],
        ],
        "reference direction (perpendicular to the axis)",
    )?;
    let y = cross(z, x);
    Ok(Frame { origin, x, y, z })
}

fn positive(x: f64, what: &str) -> Result<(), PipelineError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "the {what} must be a positive number, got {x}"
        )))
    }
}

/// Degrees to radians for an angular range `[start, end]`, `0 < end - start <= 360`.
fn angle_range(start: f64, end: f64) -> Result<(f64, f64), PipelineError> {
    if !(start.is_finite() && end.is_finite() && start < end && end - start <= 360.0) {
        return Err(invalid(format!(
            "the angles must satisfy start < end <= start + 360, got {start}..{end}"
        )));
    }
    Ok((start.to_radians(), end.to_radians()))
}

/// Builds the shape as one entity of a new document (`id` "0", `meta.shape` set).
pub fn make(shape: &MakeShape) -> Result<Document, PipelineError> {
    use std::f64::consts::{FRAC_PI_2, TAU};
    let scaled = |f: &Frame, a: f64, b: f64| -> (Point3, Point3) {
        (f.x.map(|c| c * a), f.y.map(|c| c * b))
    };
    let (geometry, kind) = match *shape {
        MakeShape::Arc {
            centre,
            normal,
            reference,
            radius,
            start,
            end,
        } => {
            positive(radius, "radius")?;
            let f = frame(centre, normal, reference)?;
            let (t0, t1) = angle_range(start, end)?;
            let (x, y) = scaled(&f, radius, radius);
            let (c, _) = conic_arc(ConicKind::Elliptic, centre, x, y, t0, t1)?;
            (Geometry::Curve(c), Shape::CircularArc)
        }
        MakeShape::Ellipse {
            centre,
            normal,
            reference,
            major,
            minor,
            start,
            end,
        } => {
            positive(major, "major semi-axis")?;
            positive(minor, "minor semi-axis")?;
            let f = frame(centre, normal, reference)?;
            let (t0, t1) = angle_range(start, end)?;
            let (x, y) = scaled(&f, major, minor);
            let (c, _) = conic_arc(ConicKind::Elliptic, centre, x, y, t0, t1)?;
            (Geometry::Curve(c), Shape::EllipticArc)
        }
        MakeShape::Line { from, to } => {
            if from == to {
                return Err(invalid("a line needs two different points"));
            }
            (
                Geometry::Curve(line_segment(from, to, 0.0, 1.0)?),
                Shape::Line,
            )
        }
        MakeShape::Cylinder {
            origin,
            axis,
            reference,
            radius,
            height,
            sweep: angle,
        } => {
            positive(radius, "radius")?;
            positive(height, "height")?;
            let f = frame(origin, axis, reference)?;
            let u = angle_range(0.0, angle)?;
            let (s, _) = sweep::cylinder(&f, radius, u, (0.0, height))?;
            (Geometry::Surface(s), Shape::Cylinder)
        }
        MakeShape::Cone {
            origin,
            axis,
            reference,
            radius,
            semi_angle,
            height,
            sweep: angle,
        } => {
            positive(height, "height")?;
            if !(radius.is_finite() && radius >= 0.0) {
                return Err(invalid(format!("the radius must be >= 0, got {radius}")));
            }
            if !(semi_angle.is_finite() && semi_angle.abs() < 90.0) {
                return Err(invalid(format!(
                    "the semi-angle must lie strictly between -90 and 90 degrees, got {semi_angle}"
                )));
            }
            let f = frame(origin, axis, reference)?;
            let u = angle_range(0.0, angle)?;
            let (s, _) = sweep::cone(&f, radius, semi_angle.to_radians(), u, (0.0, height))?;
            (Geometry::Surface(s), Shape::Cone)
        }
        MakeShape::Sphere {
            centre,
            axis,
            reference,
            radius,
        } => {
            positive(radius, "radius")?;
            let f = frame(centre, axis, reference)?;
            let (s, _) = sweep::sphere(&f, radius, (0.0, TAU), (-FRAC_PI_2, FRAC_PI_2))?;
            (Geometry::Surface(s), Shape::Sphere)
        }
        MakeShape::Torus {
            centre,
            axis,
            reference,
            major,
            minor,
        } => {
            positive(minor, "minor radius")?;
            positive(major - minor, "major radius minus the minor radius")?;
            let f = frame(centre, axis, reference)?;
            let (s, _) = sweep::torus(&f, major, minor, (0.0, TAU), (0.0, TAU))?;
            (Geometry::Surface(s), Shape::Torus)
        }
        MakeShape::Revolve {
            ref profile,
            axis_point,
            axis,
            angle,
        } => {
            let (t0, t1) = angle_range(0.0, angle)?;
            let (s, _) = sweep::revolve(profile, axis_point, unit(axis, "axis")?, t0, t1)?;
            (Geometry::Surface(s), Shape::Revolution)
        }
        MakeShape::Extrude {
            ref curve,
            direction,
        } => {
            unit(direction, "extrusion direction")?;
            let s = sweep::extrude(curve, direction, 0.0, 1.0)?;
            (Geometry::Surface(s), Shape::Extrusion)
        }
        MakeShape::Ruled {
            ref first,
            ref second,
        } => (
            Geometry::Surface(sweep::ruled(first, second)?),
            Shape::Ruled,
        ),
        MakeShape::Coons {
            ref boundaries,
            tolerance,
        } => {
            let [c0, c1, d0, d1] = &**boundaries;
            let s = crate::nurbs::coons::coons(c0, c1, d0, d1, tolerance)?;
            // A Coons patch has no ISO 10303-42 form of its own: no shape.
            return Ok(document(Geometry::Surface(s), None));
        }
    };
    Ok(document(geometry, Some(kind)))
}

/// A new document (millimetres) holding `geometry` as entity "0".
fn document(geometry: Geometry, shape: Option<Shape>) -> Document {
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    doc.entities.push(Entity {
        id: "0".into(),
        geometry,
        source: Source {
            entity: "make".into(),
            line: None,
        },
        meta: Meta {
            shape,
            ..Meta::default()
        },
    });
    doc
}

/// Reads fit points: a JSON array of `[x, y]` or `[x, y, z]`, or text with one point per
/// line (numbers separated by commas or white space; empty lines and lines starting with
/// `#` skipped). At most [`crate::nurbs::fit::MAX_FIT_POINTS`] points, counted while
/// reading. Returns the points and their dimension (2 when every point has 2 numbers).
pub fn read_points(text: &str) -> Result<(Vec<Point3>, usize), PipelineError> {
    use crate::nurbs::fit::MAX_FIT_POINTS;
    let too_many = || {
        PipelineError::new(
            super::ErrorKind::Limit,
            "limit.fit_points",
            format!("more than {MAX_FIT_POINTS} points to fit"),
            crate::exchange::Location::default(),
        )
    };
    let rows: Vec<Vec<f64>> = if text.trim_start().starts_with('[') {
        let rows: Vec<Vec<f64>> = serde_json::from_str(text).map_err(|e| {
            PipelineError::usage(
                "fit.points",
                format!("the points are not a JSON array of [x, y(, z)]: {e}"),
            )
        })?;
        if rows.len() > MAX_FIT_POINTS {
            return Err(too_many());
        }
        rows
    } else {
        let mut rows = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if rows.len() == MAX_FIT_POINTS {
                return Err(too_many());
            }
            let row = line
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
                .take(4)
                .map(|t| t.parse::<f64>())
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|e| PipelineError::usage("fit.points", format!("line {}: {e}", n + 1)))?;
            rows.push(row);
        }
        rows
    };
    let rows: Vec<&Vec<f64>> = rows.iter().collect();
    let (points, dimension) = points_of(&rows, |k| format!("point {k}"))?;
    Ok((points, dimension))
}

/// Points from rows of 2 or 3 finite numbers (all 2: a 2-D fit, z = 0), each bad row a
/// usage error naming it by `name(k)`.
fn points_of(
    rows: &[&Vec<f64>],
    name: impl Fn(usize) -> String,
) -> Result<(Vec<Point3>, usize), PipelineError> {
    let dimension = if rows.iter().all(|r| r.len() == 2) {
        2
    } else {
        3
    };
    let points = rows
        .iter()
        .enumerate()
        .map(|(k, r)| match r[..] {
            [x, y] if x.is_finite() && y.is_finite() => Ok([x, y, 0.0]),
            [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok([x, y, z]),
            _ => Err(PipelineError::usage(
                "fit.points",
                format!("{} must be 2 or 3 finite numbers, got {r:?}", name(k)),
            )),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((points, dimension))
}

/// The data of a fit: points along a curve, or a grid of points over a surface.
#[derive(Debug, Clone, PartialEq)]
pub enum FitData {
    /// Points, in order.
    Points(Vec<Point3>),
    /// Rows of points: row `i` along v at the `i`-th u.
    Grid(crate::nurbs::Grid<Point3>),
}

/// Reads fit data: a grid (a JSON array of rows of `[x, y]` or `[x, y, z]`, every row as
/// long) or points ([`read_points`]). At most [`crate::nurbs::fit::MAX_FIT_POINTS`] rows
/// and points per row, and [`crate::nurbs::fit::MAX_FIT_GRID_POINTS`] in all. Returns the
/// data and its dimension (2 when every point has 2 numbers).
pub fn read_fit_data(text: &str) -> Result<(FitData, usize), PipelineError> {
    use crate::nurbs::fit::{MAX_FIT_GRID_POINTS, MAX_FIT_POINTS};
    let grid_like = text.trim_start().strip_prefix('[').is_some_and(|rest| {
        rest.trim_start().starts_with('[') && {
            let inner = rest.trim_start()[1..].trim_start();
            inner.starts_with('[')
        }
    });
    if !grid_like {
        let (points, dimension) = read_points(text)?;
        return Ok((FitData::Points(points), dimension));
    }
    let rows: Vec<Vec<Vec<f64>>> = serde_json::from_str(text).map_err(|e| {
        PipelineError::usage(
            "fit.points",
            format!("the grid is not a JSON array of rows of [x, y(, z)]: {e}"),
        )
    })?;
    let (nu, nv) = (rows.len(), rows.first().map_or(0, Vec::len));
    if nu > MAX_FIT_POINTS || nv > MAX_FIT_POINTS || nu.saturating_mul(nv) > MAX_FIT_GRID_POINTS {
        return Err(PipelineError::new(
            super::ErrorKind::Limit,
            "limit.fit_points",
            format!(
                "a grid of {nu} x {nv} points: at most {MAX_FIT_POINTS} per direction and \
                 {MAX_FIT_GRID_POINTS} in all"
            ),
            crate::exchange::Location::default(),
        ));
    }
    if let Some(i) = rows.iter().position(|r| r.len() != nv) {
        return Err(PipelineError::usage(
            "fit.points",
            format!(
                "row {i} of the grid has {} points, row 0 has {nv}",
                rows[i].len()
            ),
        ));
    }
    let flat: Vec<&Vec<f64>> = rows.iter().flatten().collect();
    let (points, dimension) = points_of(&flat, |k| {
        format!("grid point ({}, {})", k / nv.max(1), k % nv.max(1))
    })?;
    let grid = crate::nurbs::Grid::from_u_major(nu, nv, points)
        .ok_or_else(|| PipelineError::usage("fit.points", "the grid is not rectangular"))?;
    Ok((FitData::Grid(grid), dimension))
}

/// How to fit: degrees, pole counts (absent: interpolate) and the parameter method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FitSpec {
    /// Degree (along u for a grid).
    pub degree: usize,
    /// Degree along v for a grid (default: `degree`).
    pub degree_v: Option<usize>,
    /// Pole count of a least-squares fit (along u for a grid); absent: interpolation.
    pub poles: Option<usize>,
    /// Pole count along v of a least-squares grid fit (default: `poles`).
    pub poles_v: Option<usize>,
    /// The parameter method.
    pub method: crate::nurbs::fit::ParamMethod,
}

/// What a fit did: the method, the sizes, and the measured residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitReport {
    /// `interpolation` or `least_squares`.
    pub method: &'static str,
    /// Data points (`[n]` along a curve, `[rows, columns]` of a grid).
    pub points: Vec<usize>,
    /// Poles of the result (`[n]` or `[nu, nv]`).
    pub poles: Vec<usize>,
    /// The largest distance of a data point from the result at its parameters.
    pub residual_max: f64,
    /// The root mean square of those distances.
    pub residual_rms: f64,
}

/// Fits a curve to points or a surface to a grid (`crate::nurbs::fit`: A9.1, least squares
/// of section 9.4.1, A9.4, A9.7) and returns it as a document with the fit's report.
pub fn fit(
    data: &FitData,
    dimension: usize,
    spec: FitSpec,
) -> Result<(Document, FitReport), PipelineError> {
    use crate::nurbs::fit::{SurfaceFitShape, approximate, fit_surface, interpolate};
    let method = if spec.poles.is_some() {
        "least_squares"
    } else {
        "interpolation"
    };
    match data {
        FitData::Points(points) => {
            if spec.degree_v.is_some() || spec.poles_v.is_some() {
                return Err(PipelineError::usage(
                    "fit.arguments",
                    "a degree or pole count along v needs a grid of points",
                ));
            }
            let fit = match spec.poles {
                None => interpolate(points, spec.degree, spec.method, dimension)?,
                Some(n) => approximate(points, spec.degree, n, spec.method, dimension)?,
            };
            let report = FitReport {
                method,
                points: vec![points.len()],
                poles: vec![fit.curve.num_poles()],
                residual_max: fit.residual.max,
                residual_rms: fit.residual.rms,
            };
            Ok((document(Geometry::Curve(fit.curve), None), report))
        }
        FitData::Grid(grid) => {
            if spec.poles.is_none() && spec.poles_v.is_some() {
                return Err(PipelineError::usage(
                    "fit.arguments",
                    "a pole count along v needs one along u (--poles)",
                ));
            }
            let shape = SurfaceFitShape {
                degree_u: spec.degree,
                degree_v: spec.degree_v.unwrap_or(spec.degree),
                poles: spec.poles.map(|n| (n, spec.poles_v.unwrap_or(n))),
            };
            let fit = fit_surface(grid, shape, spec.method, dimension)?;
            let net = fit.surface.control_points();
            let report = FitReport {
                method,
                points: vec![grid.nu(), grid.nv()],
                poles: vec![net.nu(), net.nv()],
                residual_max: fit.residual.max,
                residual_rms: fit.residual.rms,
            };
            Ok((document(Geometry::Surface(fit.surface), None), report))
        }
    }
}

/// The kinds `make` builds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MakeKind {
    /// A full circle.
    Circle,
    /// A circular arc.
    Arc,
    /// An ellipse or elliptic arc.
    Ellipse,
    /// A line segment.
    Line,
    /// A cylinder.
    Cylinder,
    /// A cone.
    Cone,
    /// A sphere.
    Sphere,
    /// A torus.
    Torus,
    /// A revolved curve.
    Revolve,
    /// An extruded curve.
    Extrude,
    /// A ruled surface.
    Ruled,
    /// A Coons patch.
    Coons,
}

/// The numbers and curves of a `make` request as the front ends collect them (every field
/// optional); [`shape`] checks that the kind has what it needs and fills the defaults.
#[derive(Debug, Clone, Default)]
pub struct MakeSpec {
    /// Centre (default the origin).
    pub centre: Option<Point3>,
    /// Normal or axis (default z).
    pub axis: Option<Point3>,
    /// Direction of angle 0.
    pub reference: Option<Point3>,
    /// Radius.
    pub radius: Option<f64>,
    /// Arc start angle (default 0).
    pub start: Option<f64>,
    /// Arc end angle (default 360).
    pub end: Option<f64>,
    /// Major semi-axis or radius.
    pub major: Option<f64>,
    /// Minor semi-axis or radius.
    pub minor: Option<f64>,
    /// Line start.
    pub p0: Option<Point3>,
    /// Line end.
    pub p1: Option<Point3>,
    /// Height.
    pub height: Option<f64>,
    /// Cone semi-angle.
    pub semi_angle: Option<f64>,
    /// Sweep or revolution angle (default 360).
    pub sweep: Option<f64>,
    /// A point of the revolution axis (default the origin).
    pub axis_point: Option<Point3>,
    /// Extrusion vector.
    pub direction: Option<Point3>,
    /// Corner tolerance of Coons boundaries (default 1e-9).
    pub tolerance: Option<f64>,
    /// The curves of revolve/extrude (1), ruled (2), coons (4).
    pub curves: Vec<NurbsCurve>,
}

/// The shape of `kind` from `spec`: a missing number, or the wrong number of curves, is a
/// usage error (`make.arguments`) naming the field.
pub fn shape(kind: MakeKind, spec: MakeSpec) -> Result<MakeShape, PipelineError> {
    let need =
        |v: Option<f64>, name: &str| v.ok_or_else(|| invalid(format!("this shape needs `{name}`")));
    let need_point = |v: Option<Point3>, name: &str| {
        v.ok_or_else(|| invalid(format!("this shape needs `{name}` (3 numbers)")))
    };
    let centre = spec.centre.unwrap_or([0.0; 3]);
    let axis = spec.axis.unwrap_or([0.0, 0.0, 1.0]);
    let reference = spec.reference;
    let sweep = spec.sweep.unwrap_or(360.0);
    let wanted = match kind {
        MakeKind::Revolve | MakeKind::Extrude => 1,
        MakeKind::Ruled => 2,
        MakeKind::Coons => 4,
        _ => 0,
    };
    if spec.curves.len() != wanted {
        return Err(invalid(format!(
            "this shape takes {wanted} curve(s), got {}",
            spec.curves.len()
        )));
    }
    let mut curves = spec.curves.into_iter();
    let mut next = || curves.next().ok_or_else(|| invalid("a curve is missing"));
    Ok(match kind {
        MakeKind::Circle | MakeKind::Arc => MakeShape::Arc {
            centre,
            normal: axis,
            reference,
            radius: need(spec.radius, "radius")?,
            start: if kind == MakeKind::Circle {
                0.0
            } else {
                spec.start.unwrap_or(0.0)
            },
            end: if kind == MakeKind::Circle {
                360.0
            } else {
                spec.end.unwrap_or(360.0)
            },
        },
        MakeKind::Ellipse => MakeShape::Ellipse {
            centre,
            normal: axis,
            reference,
            major: need(spec.major, "major")?,
            minor: need(spec.minor, "minor")?,
            start: spec.start.unwrap_or(0.0),
            end: spec.end.unwrap_or(360.0),
        },
        MakeKind::Line => MakeShape::Line {
            from: need_point(spec.p0, "p0")?,
            to: need_point(spec.p1, "p1")?,
        },
        MakeKind::Cylinder => MakeShape::Cylinder {
            origin: centre,
            axis,
            reference,
            radius: need(spec.radius, "radius")?,
            height: need(spec.height, "height")?,
            sweep,
        },
        MakeKind::Cone => MakeShape::Cone {
            origin: centre,
            axis,
            reference,
            radius: need(spec.radius, "radius")?,
            semi_angle: need(spec.semi_angle, "semi-angle")?,
            height: need(spec.height, "height")?,
            sweep,
        },
        MakeKind::Sphere => MakeShape::Sphere {
            centre,
            axis,
            reference,
            radius: need(spec.radius, "radius")?,
        },
        MakeKind::Torus => MakeShape::Torus {
            centre,
            axis,
            reference,
            major: need(spec.major, "major")?,
            minor: need(spec.minor, "minor")?,
        },
        MakeKind::Revolve => MakeShape::Revolve {
            profile: next()?,
            axis_point: spec.axis_point.unwrap_or([0.0; 3]),
            axis,
            angle: sweep,
        },
        MakeKind::Extrude => MakeShape::Extrude {
            curve: next()?,
            direction: need_point(spec.direction, "direction")?,
        },
        MakeKind::Ruled => MakeShape::Ruled {
            first: next()?,
            second: next()?,
        },
        MakeKind::Coons => MakeShape::Coons {
            boundaries: Box::new([next()?, next()?, next()?, next()?]),
            tolerance: spec.tolerance.unwrap_or(1e-9),
        },
    })
}
