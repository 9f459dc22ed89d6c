//! STEP geometry other than B-splines -> exact NURBS entities: lines, conics, polylines,
//! trimmed and composite curves, surface curves, the elementary and swept surfaces and
//! rectangular trimmed surfaces (ISO 10303-42 4.4), bounded by their use (edges by their
//! vertices, faces by their edges, trims by their trim values).
//!
//! Parameters (the policy README's parameterisation table states):
//! - lines, parabolas, polylines, plane and axial directions: the NURBS parameter is the
//!   ISO 10303-42 parameter (identity);
//! - circles, ellipses, hyperbolas and every angular direction (cylinder, cone, sphere,
//!   torus, revolution): the NURBS parameter equals the ISO angle (or hyperbolic parameter)
//!   at every knot and is related to it in between by the exact [`ArcMap`] of
//!   [`conic_arc`] (the NURBS Book A7.1 arcs);
//! - B-splines keep their own parameter; a trimmed or split piece keeps it too (A5.1 knot
//!   insertion does not move parameters); a piece wrapped over the seam of a closed curve
//!   continues past its end (`t + period`);
//! - `sense_agreement = .F.` (and `usense`/`vsense = .F.`) reverses: `u' = a + b - u` on the
//!   piece's domain `[a, b]`;
//! - a composite curve's segments follow each other: segment i is shifted to start where
//!   segment i - 1 ends, the first starts at 0 (ISO 10303-42 composite_curve).
//!
//! Angles in the file (conic trims, `semi_angle`, rectangular trims of angular directions)
//! are in the file's plane-angle unit and are converted to radians exactly once, here, by
//! [`Converter::angle`].

/// The id-keyed maps and sets of the conversion: foldhash's `quality` hasher, as [`Items`].
pub(super) type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::quality::RandomState>;
/// See [`HashMap`].
type HashSet<K> = std::collections::HashSet<K, foldhash::quality::RandomState>;
use std::borrow::Cow;
use std::f64::consts::{FRAC_PI_2, TAU};

use nurbsx_parsers::step::geometry::{
    GeometryEntity, GeometryItem, GeometryRecord as R, RectangularTrim, Trimming, TrimmingSelect,
};
use nurbsx_parsers::step::schema::names_bspline_surface;
use nurbsx_parsers::step::{RawInstance, Scanned};

use crate::exchange::{Diagnostic, Entity, Label, Location, Meta, Shape, Source};
use crate::nurbs::conic::{ConicKind, conic_arc, line_segment, parabola_arc, polyline};
use crate::nurbs::project::invert_curve;
use crate::nurbs::sweep::{self, Frame, QuadricMap};
use crate::nurbs::vector::{add, sub};
use crate::nurbs::vector::{cross, dot, norm, scale as mul};
use crate::nurbs::{
    Geometry, GeometryError, NurbsCurve, NurbsSurface, Point3, bounding_box_diagonal,
};

/// Deepest chain of curves built on curves (trimmed over composite over trimmed...) that is
/// followed; files nest two or three. Deeper input is refused with a located error (no
/// input-controlled recursion depth).
const MAX_NESTING: usize = 16;

/// ISO 10303-42 `normalise`: `None` for a zero (or non-finite) vector.
fn normalise(a: Point3) -> Option<Point3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| mul(a, 1.0 / n))
}

/// ISO 10303-42 function `first_proj_axis(z_axis, arg)`: the projection of `arg` (default
/// (1,0,0), or (0,1,0) when z is +-(1,0,0)) onto the plane normal to z, normalised. `None`
/// when `arg` is parallel to z.
pub(super) fn first_proj_axis(z: Point3, arg: Option<Point3>) -> Option<Point3> {
    let v = match arg {
        None => {
            if z != [1.0, 0.0, 0.0] && z != [-1.0, 0.0, 0.0] {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            }
        }
        Some(a) => {
            if norm(cross(a, z)) == 0.0 {
                return None;
            }
            normalise(a)?
        }
    };
    normalise(sub(v, mul(z, dot(v, z))))
}

/// The axes a reader builds from an AXIS2_PLACEMENT_3D whose DIRECTIONs hold `axis` and
/// `ref_direction`: each direction normalised as read, then [`build_axes`].
pub(super) fn axes_as_read(axis: Point3, ref_direction: Point3) -> Option<Frame> {
    build_axes(Some(normalise(axis)?), Some(normalise(ref_direction)?))
}

/// ISO 10303-42 function `build_axes(axis, ref_direction)`: `[x, y, z]` with
/// `z = NVL(normalise(axis), (0,0,1))`, `x = first_proj_axis(z, ref_direction)`,
/// `y = normalise(z x x)`.
pub(super) fn build_axes(axis: Option<Point3>, ref_direction: Option<Point3>) -> Option<Frame> {
    let z = match axis {
        Some(a) => normalise(a)?,
        None => [0.0, 0.0, 1.0],
    };
    let x = first_proj_axis(z, ref_direction)?;
    let y = normalise(cross(z, x))?;
    Some(Frame {
        origin: [0.0; 3],
        x,
        y,
        z,
    })
}

/// A curve in ISO 10303-42 terms, before it is bounded.
#[derive(Debug, Clone)]
pub(super) enum Basis {
    /// `P(t) = p + t d` (d with its magnitude).
    Line { p: Point3, d: Point3 },
    /// `C + cos t X + sin t Y` (elliptic) or `C + cosh t X + sinh t Y` (hyperbolic).
    Conic {
        kind: ConicKind,
        c: Point3,
        x: Point3,
        y: Point3,
        shape: Shape,
    },
    /// `V + t^2 X + 2 t Y`.
    Parabola { v: Point3, x: Point3, y: Point3 },
    /// A curve that is already a NURBS (B-spline, polyline, trimmed, composite): its
    /// parameter is the NURBS parameter.
    Nurbs {
        curve: NurbsCurve,
        shape: Option<Shape>,
        /// The metadata of the B-spline instance as read, when the basis is one (not built
        /// here; the reader's B-spline path converts it).
        bspline: Option<Box<Meta>>,
    },
}

impl Basis {
    fn shape(&self) -> Option<Shape> {
        match self {
            Basis::Line { .. } => Some(Shape::Line),
            Basis::Conic { shape, .. } => Some(*shape),
            Basis::Parabola { .. } => Some(Shape::ParabolicArc),
            Basis::Nurbs { shape, .. } => *shape,
        }
    }

    /// The parameter range of the whole curve, `None` when unbounded.
    fn natural_range(&self) -> Option<(f64, f64)> {
        match self {
            Basis::Conic {
                kind: ConicKind::Elliptic,
                ..
            } => Some((0.0, TAU)),
            Basis::Nurbs { curve, .. } => Some(curve.domain()),
            _ => None,
        }
    }

    /// The period of a closed curve (circle, ellipse, a NURBS whose ends meet).
    fn period(&self) -> Option<f64> {
        match self {
            Basis::Conic {
                kind: ConicKind::Elliptic,
                ..
            } => Some(TAU),
            Basis::Nurbs { curve, .. } => {
                let (a, b) = curve.domain();
                let gap = norm(sub(
                    curve.point_at_unchecked(a),
                    curve.point_at_unchecked(b),
                ));
                (gap <= super::closure_tolerance(curve.control_points())).then_some(b - a)
            }
            _ => None,
        }
    }

    /// The point at ISO parameter `t`.
    fn point(&self, t: f64) -> Point3 {
        match self {
            Basis::Line { p, d } => add(*p, mul(*d, t)),
            Basis::Conic { kind, c, x, y, .. } => {
                let (a, b) = match kind {
                    ConicKind::Elliptic => (t.cos(), t.sin()),
                    ConicKind::Hyperbolic => (t.cosh(), t.sinh()),
                };
                add(*c, add(mul(*x, a), mul(*y, b)))
            }
            Basis::Parabola { v, x, y } => add(*v, add(mul(*x, t * t), mul(*y, 2.0 * t))),
            Basis::Nurbs { curve, .. } => curve.point_at_unchecked(t),
        }
    }

    /// The exact inverse of the parameterisation at a point of the curve (lines and conics;
    /// X and Y are orthogonal here, built from an orthonormal placement). `None` for a NURBS.
    fn inverse(&self, q: Point3) -> Option<f64> {
        match self {
            Basis::Line { p, d } => Some(dot(sub(q, *p), *d) / dot(*d, *d)),
            Basis::Conic { kind, c, x, y, .. } => {
                let r = sub(q, *c);
                let cx = dot(r, *x) / dot(*x, *x);
                let sy = dot(r, *y) / dot(*y, *y);
                Some(match kind {
                    ConicKind::Elliptic => sy.atan2(cx),
                    ConicKind::Hyperbolic => sy.asinh(),
                })
            }
            Basis::Parabola { v, y, .. } => Some(dot(sub(q, *v), *y) / (2.0 * dot(*y, *y))),
            // No exact inverse inside a B-spline; its end points are its domain ends.
            Basis::Nurbs { curve, .. } => {
                let (a, b) = curve.domain();
                let tol = super::closure_tolerance(curve.control_points());
                if norm(sub(q, curve.point_at_unchecked(a))) <= tol {
                    Some(a)
                } else if norm(sub(q, curve.point_at_unchecked(b))) <= tol {
                    Some(b)
                } else {
                    None
                }
            }
        }
    }

    /// The curve on ISO parameters `[a, b]`, `a < b` (for a closed curve `b - a` at most one
    /// period; `a` and `b` may lie past the seam).
    fn bounded(&self, a: f64, b: f64) -> Result<NurbsCurve, GeometryError> {
        match self {
            Basis::Line { p, d } => line_segment(add(*p, mul(*d, a)), add(*p, mul(*d, b)), a, b),
            Basis::Conic { kind, c, x, y, .. } => Ok(conic_arc(*kind, *c, *x, *y, a, b)?.0),
            Basis::Parabola { v, x, y } => parabola_arc(*v, *x, *y, a, b),
            Basis::Nurbs { curve, .. } => {
                let (s, e) = curve.domain();
                match self.period() {
                    Some(p) => {
                        // Bring a into [s, e) (b follows), then wrap over the seam if needed.
                        let k = ((a - s) / p).floor();
                        let (a, b) = (a - k * p, b - k * p);
                        if b <= e + 1e-12 * p {
                            curve.piece(a, b.min(e))
                        } else {
                            let first = curve.piece(a, e)?;
                            let second = curve.piece(s, b - p)?;
                            first.join(&second, super::closure_tolerance(curve.control_points()))
                        }
                    }
                    None => curve.piece(a, b),
                }
            }
        }
    }
}

/// `[lo, hi]` of a range running from `from` to `to` along increasing parameter: for a
/// closed curve or angular direction (period `p`) the end is moved by whole periods to lie
/// in `(from, from + p]` (equal values mean the whole period).
fn forward_range(from: f64, to: f64, period: Option<f64>) -> Option<(f64, f64)> {
    match period {
        Some(p) => {
            let mut d = (to - from).rem_euclid(p);
            if d <= 1e-12 * p {
                d = p;
            }
            Some((from, from + d))
        }
        None => (to > from).then_some((from, to)),
    }
}

/// A parameter range in u and in v, `None` where a direction has none.
type Box2 = (Option<(f64, f64)>, Option<(f64, f64)>);

/// A surface in ISO 10303-42 terms, before it is bounded.
#[derive(Debug, Clone)]
enum SurfaceBasis {
    Plane(Frame),
    Cylinder(Frame, f64),
    Cone(Frame, f64, f64),
    Sphere(Frame, f64),
    Torus(Frame, f64, f64, (f64, f64)),
    Revolution {
        profile: Basis,
        point: Point3,
        axis: Point3,
    },
    Extrusion {
        profile: Basis,
        d: Point3,
    },
    Nurbs(NurbsSurface),
}

impl SurfaceBasis {
    fn shape(&self) -> Option<Shape> {
        Some(match self {
            SurfaceBasis::Plane(_) => Shape::Plane,
            SurfaceBasis::Cylinder(..) => Shape::Cylinder,
            SurfaceBasis::Cone(..) => Shape::Cone,
            SurfaceBasis::Sphere(..) => Shape::Sphere,
            SurfaceBasis::Torus(..) => Shape::Torus,
            SurfaceBasis::Revolution { .. } => Shape::Revolution,
            SurfaceBasis::Extrusion { .. } => Shape::Extrusion,
            SurfaceBasis::Nurbs(_) => return None,
        })
    }

    /// Ranges of the whole surface in u and v (`None` = unbounded direction).
    fn natural(&self) -> Box2 {
        let turn = Some((0.0, TAU));
        match self {
            SurfaceBasis::Plane(_) => (None, None),
            SurfaceBasis::Cylinder(..) | SurfaceBasis::Cone(..) => (turn, None),
            SurfaceBasis::Sphere(..) => (turn, Some((-FRAC_PI_2, FRAC_PI_2))),
            SurfaceBasis::Torus(_, _, _, v) => (turn, Some(*v)),
            SurfaceBasis::Revolution { profile, .. } => (turn, profile.natural_range()),
            SurfaceBasis::Extrusion { profile, .. } => (profile.natural_range(), None),
            SurfaceBasis::Nurbs(s) => {
                let (u, v) = s.domain();
                (Some(u), Some(v))
            }
        }
    }

    /// Periods of the u and v directions (angles, closed profiles).
    fn periods(&self) -> (Option<f64>, Option<f64>) {
        match self {
            SurfaceBasis::Plane(_) | SurfaceBasis::Nurbs(_) => (None, None),
            SurfaceBasis::Cylinder(..) | SurfaceBasis::Cone(..) | SurfaceBasis::Sphere(..) => {
                (Some(TAU), None)
            }
            SurfaceBasis::Torus(_, big, small, _) => (Some(TAU), (big >= small).then_some(TAU)),
            SurfaceBasis::Revolution { profile, .. } => (Some(TAU), profile.period()),
            SurfaceBasis::Extrusion { profile, .. } => (profile.period(), None),
        }
    }

    /// Which ISO 10303-42 parameters are lengths (scaled with the length unit) and which
    /// are angles (in the plane-angle unit), for a rectangular trim.
    fn units(&self) -> (Param, Param) {
        match self {
            SurfaceBasis::Plane(_) => (Param::Length, Param::Length),
            SurfaceBasis::Cylinder(..) | SurfaceBasis::Cone(..) => (Param::Angle, Param::Length),
            SurfaceBasis::Sphere(..) | SurfaceBasis::Torus(..) => (Param::Angle, Param::Angle),
            SurfaceBasis::Revolution { profile, .. } => (Param::Angle, curve_param(profile)),
            SurfaceBasis::Extrusion { profile, .. } => (curve_param(profile), Param::Plain),
            SurfaceBasis::Nurbs(_) => (Param::Plain, Param::Plain),
        }
    }

    /// The NURBS surface over `u x v`, with the closed-form inverse of its parameterisation
    /// for the quadrics ([`QuadricMap`]; `None` for the other kinds).
    fn build(
        &self,
        u: (f64, f64),
        v: (f64, f64),
    ) -> Result<(NurbsSurface, Option<QuadricMap>), GeometryError> {
        let mapped = |(s, m): (NurbsSurface, QuadricMap)| (s, Some(m));
        let surface = match self {
            SurfaceBasis::Plane(f) => sweep::plane(f, u, v),
            SurfaceBasis::Cylinder(f, r) => return sweep::cylinder(f, *r, u, v).map(mapped),
            SurfaceBasis::Cone(f, r, a) => return sweep::cone(f, *r, *a, u, v).map(mapped),
            SurfaceBasis::Sphere(f, r) => return sweep::sphere(f, *r, u, v).map(mapped),
            SurfaceBasis::Torus(f, big, small, _) => {
                return sweep::torus(f, *big, *small, u, v).map(mapped);
            }
            SurfaceBasis::Revolution {
                profile,
                point,
                axis,
            } => Ok(sweep::revolve(&profile.bounded(v.0, v.1)?, *point, *axis, u.0, u.1)?.0),
            SurfaceBasis::Extrusion { profile, d } => {
                sweep::extrude(&profile.bounded(u.0, u.1)?, *d, v.0, v.1)
            }
            SurfaceBasis::Nurbs(s) => {
                // A trim reaching past the knot domain keeps the domain's end there.
                let ((u0, u1), (v0, v1)) = s.domain();
                s.piece((u.0.max(u0), u.1.min(u1)), (v.0.max(v0), v.1.min(v1)))
            }
        };
        surface.map(|s| (s, None))
    }
}

/// What kind of value an ISO parameter is, for unit conversion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Param {
    /// A length (scaled by the length factor).
    Length,
    /// A plane angle (converted to radians).
    Angle,
    /// A pure number (B-spline, line and parabola parameters).
    Plain,
}

fn curve_param(b: &Basis) -> Param {
    match b {
        Basis::Conic {
            kind: ConicKind::Elliptic,
            ..
        } => Param::Angle,
        _ => Param::Plain,
    }
}

/// A decoded geometry item as the reader keeps it: the most specific entity type read, the
/// attributes, and where the item's provenance needs no second reading of its instance. The
/// name and the entity type as written, which only the entities and origins made from it
/// need, are read again from the instance then ([`Converter::provenance`]) unless the
/// instance is plain (a simple instance with an empty name: its type as written is
/// `entity`, and it has no name): holding them for every item made each 136 bytes with its
/// id instead of 64, and the items are the read's largest structure.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Kept<'a> {
    /// [`GeometryItem::record`].
    pub record: R<'a>,
    /// [`GeometryItem::entity`].
    pub entity: GeometryEntity,
    /// Whether the instance is simple and its name empty.
    plain: bool,
    /// The instance's 1-based line when it was looked up while the instance was decoded
    /// (plain items of the kinds that become entities and origins), else 0.
    line: u32,
}

impl<'a> Kept<'a> {
    /// The item of `item`, whose instance is at `offset` of the text `s` indexes.
    pub(super) fn new(item: GeometryItem<'a>, s: &Scanned<'_>, offset: usize) -> Self {
        // The decoders name a simple instance's type by the table's own text: the same
        // text is the same type without comparing it (a `memcmp` per item otherwise).
        let name = item.entity.name();
        let same_type = std::ptr::eq(item.entity_type.as_ref(), name) || item.entity_type == name;
        let plain = item.name.as_ref().is_none_or(|n| n.raw.is_empty()) && same_type;
        // Placements, directions, oriented edges, loops, bounds, pcurves and surface curves
        // (an edge's entity is its 3-D curve) become no entity or origin of their own: their
        // line is not looked up.
        let own = !matches!(
            item.record,
            R::Direction { .. }
                | R::Vector { .. }
                | R::Axis1Placement { .. }
                | R::Axis2Placement2d { .. }
                | R::Axis2Placement3d { .. }
                | R::OrientedEdge { .. }
                | R::EdgeLoop { .. }
                | R::FaceBound { .. }
                | R::Pcurve { .. }
                | R::DefinitionalRepresentation { .. }
                | R::SurfaceCurve { .. }
        );
        let line = if plain && own {
            u32::try_from(s.line(offset)).unwrap_or(0)
        } else {
            0
        };
        Kept {
            record: item.record,
            entity: item.entity,
            plain,
            line,
        }
    }
}

/// The decoded geometry items by instance id, held in one vector in ascending id order
/// (no per-item allocation, no hash table slack: the items are the read's largest
/// structure). An id is found through a slot table indexed by id when the ids are dense
/// (the largest at most four times their count, as in files written by CAD systems), by
/// binary search otherwise, so ids chosen to be sparse or to collide cost at most a
/// logarithm.
#[derive(Default)]
pub(super) struct Items<'a> {
    /// The items, ids ascending and unique.
    entries: Vec<(u64, Kept<'a>)>,
    /// `slots[id]` is the item's position in `entries` ([`Items::NONE`] for none); empty
    /// when the ids are sparse.
    slots: Vec<u32>,
}

impl<'a> Items<'a> {
    /// A slot with no item.
    const NONE: u32 = u32::MAX;

    /// The items `(id, item)`, in any order; of a repeated id the first is kept (the
    /// reader decodes only the indexed instance of a duplicated id).
    #[cfg(test)]
    pub(super) fn new(entries: Vec<(u64, Kept<'a>)>) -> Self {
        Self::gather(entries, Some)
    }

    /// The items `item(x)` makes of `list`'s `(id, x)` (those it gives), in any order; of a
    /// repeated id the first is kept. Files list instances in ascending id order almost
    /// always: then one pass, in place where `x` and an item are of one size (the standard
    /// library reuses `list`'s buffer), keeps the items, checks the order, drops repeated
    /// ids and fills the slot table (each pass over the items is a pass over the read's
    /// largest structure); the items are sorted and their table built afterwards only when
    /// the ids turn out not to ascend.
    pub(super) fn gather<T>(
        list: Vec<(u64, T)>,
        mut item: impl FnMut(T) -> Option<Kept<'a>>,
    ) -> Self {
        // Ids above this make the table too sparse whatever is kept
        // (`Items::dense_table`); the table is not grown past it.
        let limit = list.len().saturating_mul(4).saturating_add(1024);
        let hint = list
            .last()
            .and_then(|(id, _)| usize::try_from(*id).ok())
            .map_or(0, |id| id.min(limit).saturating_add(1));
        let mut slots: Vec<u32> = Vec::with_capacity(hint);
        let (mut ascending, mut dense) = (true, true);
        let mut last: Option<u64> = None;
        let mut count: usize = 0;
        let mut entries: Vec<(u64, Kept<'a>)> = list
            .into_iter()
            .filter_map(|(id, x)| {
                let kept = item(x)?;
                if ascending {
                    match last {
                        Some(l) if id == l => return None,
                        Some(l) if id < l => ascending = false,
                        _ => {}
                    }
                }
                if ascending && dense {
                    match (
                        usize::try_from(id).ok().filter(|&i| i <= limit),
                        u32::try_from(count),
                    ) {
                        // Ascending ids: the table ends before `i`.
                        (Some(i), Ok(k)) => {
                            if slots.len() < i {
                                slots.resize(i, Self::NONE);
                            }
                            slots.push(k);
                        }
                        _ => dense = false,
                    }
                }
                last = Some(id);
                count += 1;
                Some((id, kept))
            })
            .collect();
        entries.shrink_to_fit();
        if !ascending {
            entries.sort_by_key(|(id, _)| *id);
            entries.dedup_by_key(|(id, _)| *id);
            let slots = Self::slots(&entries);
            return Items { entries, slots };
        }
        if dense && Self::dense_table(&entries).is_some() {
            slots.shrink_to_fit();
        } else {
            slots = Vec::new();
        }
        Items { entries, slots }
    }

    /// The largest id of `entries` (sorted by id) when the ids are dense enough for a slot
    /// table: the largest at most four times their count (plus 1024), the positions within
    /// a `u32`. `None` when lookups should search instead.
    fn dense_table(entries: &[(u64, Kept<'a>)]) -> Option<usize> {
        let max = entries.last().map_or(0, |(id, _)| *id);
        usize::try_from(max).ok().filter(|&m| {
            m <= entries.len().saturating_mul(4).saturating_add(1024)
                && u32::try_from(entries.len()).is_ok()
        })
    }

    /// The dense id -> entry index of `entries` (sorted by id), or none when the ids are
    /// too sparse for one (lookups then search).
    fn slots(entries: &[(u64, Kept<'a>)]) -> Vec<u32> {
        let mut slots = Vec::new();
        if let Some(m) = Self::dense_table(entries) {
            slots = vec![Self::NONE; m + 1];
            for (k, (id, _)) in entries.iter().enumerate() {
                if let (Some(cell), Ok(k)) = (
                    usize::try_from(*id).ok().and_then(|i| slots.get_mut(i)),
                    u32::try_from(k),
                ) {
                    *cell = k;
                }
            }
        }
        slots
    }

    /// Keeps the items `keep` accepts and frees the room of the others. The slot table is
    /// updated in place as the items are walked (once each, in order: the kept ones take
    /// the next positions), not built again (its memory set and filled anew were a visible
    /// part of a large read).
    pub(super) fn retain(&mut self, mut keep: impl FnMut(u64, &R<'a>) -> bool) {
        let slots = &mut self.slots;
        let mut next: u32 = 0;
        self.entries.retain(|(id, item)| {
            let kept = keep(*id, &item.record);
            if let Some(cell) = usize::try_from(*id).ok().and_then(|i| slots.get_mut(i)) {
                *cell = if kept { next } else { Self::NONE };
            }
            // Fewer entries than before, whose positions fit a slot (`Items::slots`).
            next += u32::from(kept);
            kept
        });
        self.entries.shrink_to_fit();
        // Cut after the largest id left. The table is kept even where the items left are
        // too few for the density rule of `Items::slots` (a B-rep keeps about a quarter of
        // its ids): its size
        // was bounded by the items it was made for, and the topology's look-ups, most of a
        // large read's, would search instead.
        let last = self.entries.last().map_or(0, |(id, _)| *id);
        if let Ok(last) = usize::try_from(last) {
            self.slots.truncate(last.saturating_add(1));
            self.slots.shrink_to_fit();
        }
    }

    /// The item `#id`.
    #[inline]
    pub(super) fn get(&self, id: &u64) -> Option<&Kept<'a>> {
        let k = self.position(*id)?;
        self.entries.get(k).map(|(_, item)| item)
    }

    /// The position of item `#id` in the ascending order of [`Items::iter`].
    #[inline]
    pub(super) fn position(&self, id: u64) -> Option<usize> {
        if self.slots.is_empty() {
            return self.entries.binary_search_by_key(&id, |(i, _)| *i).ok();
        }
        let slot = *self.slots.get(usize::try_from(id).ok()?)?;
        if slot == Self::NONE {
            return None;
        }
        usize::try_from(slot).ok()
    }

    /// The number of items.
    pub(super) fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether `#id` is an item.
    pub(super) fn contains_key(&self, id: &u64) -> bool {
        self.get(id).is_some()
    }

    /// The items with their ids, ascending.
    pub(super) fn iter(&self) -> impl Iterator<Item = (u64, &Kept<'a>)> {
        self.entries.iter().map(|(id, item)| (*id, item))
    }

    /// The items, in ascending id order.
    pub(super) fn values(&self) -> impl Iterator<Item = &Kept<'a>> {
        self.entries.iter().map(|(_, item)| item)
    }

    /// Whether there is no item.
    pub(super) fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// Whether an item that nothing else uses becomes an entity of its own (or a diagnostic)
/// in [`Converter::free_item`]: the curves and surfaces (the other items are parts of
/// them: placements, directions, topology).
pub(super) fn stands_alone(record: &R<'_>) -> bool {
    matches!(
        record,
        R::Line { .. }
            | R::Hyperbola { .. }
            | R::Parabola { .. }
            | R::TrimmedCurve { .. }
            | R::Circle { .. }
            | R::Ellipse { .. }
            | R::Polyline { .. }
            | R::CompositeCurve { .. }
            | R::SurfaceCurve { .. }
            | R::Plane { .. }
            | R::CylindricalSurface { .. }
            | R::ConicalSurface { .. }
            | R::SphericalSurface { .. }
            | R::ToroidalSurface { .. }
            | R::SurfaceOfRevolution { .. }
            | R::SurfaceOfLinearExtrusion { .. }
            | R::RectangularTrimmedSurface { .. }
            | R::Offset { .. }
    )
}

/// The faces of each surface that faces use: the surfaces ascending, each with its faces in
/// item order, in three lists (a hash table of a vector per surface was an allocation and
/// a hashing per face surface).
struct FacesOf {
    /// The surfaces, ascending and unique.
    surfaces: Vec<u64>,
    /// Where each surface's faces start in `faces` (one more entry: the end).
    starts: Vec<usize>,
    /// The faces, grouped by surface.
    faces: Vec<u64>,
}

impl FacesOf {
    /// From `(surface, face)` pairs in item order.
    fn new(mut pairs: Vec<(u64, u64)>) -> Self {
        // Stable: each surface's faces stay in item order.
        pairs.sort_by_key(|&(surface, _)| surface);
        let mut surfaces = Vec::new();
        let mut starts = Vec::new();
        let mut at = 0;
        for run in pairs.chunk_by(|a, b| a.0 == b.0) {
            if let Some(&(surface, _)) = run.first() {
                surfaces.push(surface);
                starts.push(at);
            }
            at += run.len();
        }
        starts.push(pairs.len());
        FacesOf {
            surfaces,
            starts,
            faces: pairs.into_iter().map(|(_, face)| face).collect(),
        }
    }

    /// The faces of the `k`-th surface.
    fn faces(&self, k: usize) -> &[u64] {
        match (self.starts.get(k), self.starts.get(k + 1)) {
            (Some(&a), Some(&b)) => self.faces.get(a..b).unwrap_or_default(),
            _ => &[],
        }
    }

    /// Whether faces use surface `#id`.
    fn contains(&self, id: u64) -> bool {
        self.surfaces.binary_search(&id).is_ok()
    }

    /// The number of surfaces.
    fn len(&self) -> usize {
        self.surfaces.len()
    }
}

/// One converted entity with the byte offset of its instance (for file order).
pub(super) type Placed = (usize, Entity);

/// A converted face surface and the closed-form inverse of its parameterisation (quadrics).
type FaceSurface = (Placed, Option<QuadricMap>);

/// Turns the decoded geometry items into entities.
pub(super) struct Converter<'m, 's, 'a> {
    pub s: &'s Scanned<'a>,
    pub items: &'m Items<'a>,
    /// Length factor applied to coordinates.
    pub scale: f64,
    /// Radians per unit of the file's plane angle.
    pub radians: f64,
    /// The file's length uncertainty in the model's unit (0 when it declares none).
    pub uncertainty: f64,
    /// Converts a B-spline instance (the reader's own B-spline path).
    pub bspline: &'m (dyn Fn(&RawInstance<'a>) -> Result<Option<Entity>, Diagnostic> + Sync),
    /// Warnings found while converting (parallel workers push here).
    pub warnings: std::sync::Mutex<Vec<Diagnostic>>,
    /// The points the conversion reads, read once ([`Converter::run`] fills it).
    points: std::sync::OnceLock<Points>,
}

/// The CARTESIAN_POINTs that placements, vertices and the 3-D lines of edges name, read
/// once each, in id order (file order, as the text lies), their coordinates as written
/// (unscaled): [`Converter::point`] finds them here instead of reading each one's text
/// wherever it is used (a vertex's point once per edge end and again for the topology),
/// by then long out of the cache. A point that does not read is not held: its users read
/// it themselves and report what is wrong.
#[derive(Default)]
pub(super) struct Points {
    /// `(id, coordinates)`, ids ascending and unique.
    read: Vec<(u64, Point3)>,
}

impl Points {
    /// The points `#id` of `ids` (any order, repeats allowed) of `s`.
    fn read(s: &Scanned<'_>, mut ids: Vec<u64>) -> Self {
        use rayon::prelude::*;
        ids.sort_unstable();
        ids.dedup();
        let read: Vec<Option<(u64, Point3)>> = ids
            .par_iter()
            .map(|&id| {
                let raw = s.get(id)?;
                s.cartesian_point(raw).ok().map(|(c, _)| (id, c))
            })
            .collect();
        Points {
            read: read.into_iter().flatten().collect(),
        }
    }

    /// The coordinates of point `#id`, when held.
    fn get(&self, id: u64) -> Option<Point3> {
        let k = self.read.binary_search_by_key(&id, |(i, _)| *i).ok()?;
        self.read.get(k).map(|(_, c)| *c)
    }
}

/// The file's units as the conversion applies them (see [`Converter`]'s fields).
#[derive(Clone, Copy)]
pub(super) struct Units {
    pub scale: f64,
    pub radians: f64,
    pub uncertainty: f64,
}

impl<'m, 's, 'a> Converter<'m, 's, 'a> {
    /// A converter of `items` with no warnings yet.
    pub(super) fn new(
        s: &'s Scanned<'a>,
        items: &'m Items<'a>,
        units: Units,
        bspline: &'m (dyn Fn(&RawInstance<'a>) -> Result<Option<Entity>, Diagnostic> + Sync),
    ) -> Self {
        Converter {
            s,
            items,
            scale: units.scale,
            radians: units.radians,
            uncertainty: units.uncertainty,
            bspline,
            warnings: std::sync::Mutex::new(Vec::new()),
            points: std::sync::OnceLock::new(),
        }
    }

    /// The points this converter read ([`Converter::run`]), for a converter of the same
    /// file after it ([`Converter::with_points`]).
    pub(super) fn into_points(self) -> Option<Points> {
        self.points.into_inner()
    }

    /// This converter with the points an earlier one of the same file read.
    pub(super) fn with_points(self, points: Option<Points>) -> Self {
        if let Some(p) = points {
            let _ = self.points.set(p);
        }
        self
    }
}

/// What a conversion run produced.
#[derive(Default)]
pub(super) struct Output {
    /// Entities with the offsets of their instances.
    pub entities: Vec<Placed>,
    /// Diagnostics, in no particular order (the reader sorts them by line).
    pub diagnostics: Vec<Diagnostic>,
    /// B-spline instances that became part of another entity (a trimmed or composite curve,
    /// a swept or rectangular trimmed surface): not converted again on their own.
    pub consumed_bsplines: HashSet<u64>,
    /// The converted EDGE_CURVEs with their instance ids, in item order (for the topology,
    /// which builds them in that order).
    pub edges: Vec<(u64, EdgeOut)>,
    /// Every EDGE_CURVE item's id, converted or not, in item order (the topology reads their
    /// pcurves: `topology::edge_pcurve_curves`).
    pub edge_items: Vec<u64>,
    /// The closed-form inverses of the face surfaces that are quadrics, by surface instance
    /// id (for the pcurves of the topology).
    pub quadric_maps: HashMap<u64, QuadricMap>,
    /// The warning that the file's analytic pcurves (2-D lines and conics in a surface's
    /// parameter plane) are not represented: the reader gives it when it reads geometry
    /// only. A whole-part reading carries every coedge's pcurve, computed on the face's
    /// NURBS surface (`topology::edge_pcurve`), so the file's own pcurves are not lost there
    /// (a coedge left without one has its own `pcurve.not_computed` warning).
    pub analytic_pcurves: Option<Diagnostic>,
}

type Res<T> = Result<T, Diagnostic>;

impl<'a> Converter<'_, '_, 'a> {
    /// How far an edge's vertex may be from its curve of extent `size`: 1e-7 of the size,
    /// or the file's length uncertainty when larger (ISO 10303-43: points closer than it
    /// are the same), but never more than a thousandth of the size.
    fn vertex_tolerance(&self, size: f64) -> f64 {
        (size * 1e-7)
            .max(1e-9)
            .max(self.uncertainty.min(size * 1e-3))
    }

    pub(super) fn location(&self, id: u64) -> Location {
        let (line, column) = self.line_column(id);
        Location {
            line: (line > 0).then_some(line),
            column: (column > 0).then_some(column),
            entity: Some(super::instance_label(id).into()),
            ..Location::default()
        }
    }

    /// The 1-based line and column where instance `#id` starts; (0, 0) when it is not in
    /// the file.
    fn line_column(&self, id: u64) -> (usize, usize) {
        self.s
            .get(id)
            .map_or((0, 0), |raw| self.s.locate(raw.offset()))
    }

    pub(super) fn error(&self, id: u64, code: &str, message: impl Into<String>) -> Diagnostic {
        Diagnostic::error(code, message, self.location(id))
    }

    /// An OFFSET_CURVE/OFFSET_SURFACE: refused, located at the entity.
    fn unsupported(&self, id: u64, item: &Kept<'_>) -> Diagnostic {
        self.error(
            id,
            "geometry.unsupported",
            format!(
                "{} has no exact rational form; not represented",
                item.entity
            ),
        )
        .not_carried()
    }

    fn geometry_error(&self, id: u64, e: GeometryError) -> Diagnostic {
        self.error(id, "geometry.invalid", e.to_string())
    }

    /// A plane angle of the file in radians (the one conversion of the file's unit).
    fn angle(&self, value: f64) -> f64 {
        value * self.radians
    }

    fn convert_param(&self, kind: Param, value: f64) -> f64 {
        match kind {
            Param::Length => value * self.scale,
            Param::Angle => self.angle(value),
            Param::Plain => value,
        }
    }

    fn item(&self, id: u64, from: u64, what: &str) -> Res<&Kept<'a>> {
        self.items.get(&id).ok_or_else(|| {
            self.error(
                from,
                "step.reference",
                format!("#{from} references #{id}, which is not a usable {what}"),
            )
        })
    }

    pub(super) fn point(&self, id: u64, from: u64) -> Res<Point3> {
        if let Some(c) = self.points.get().and_then(|p| p.get(id)) {
            return Ok(mul(c, self.scale));
        }
        let raw = self
            .s
            .get(id)
            .ok_or_else(|| self.error(from, "step.reference", format!("#{id} is not defined")))?;
        let (c, _) = self.s.cartesian_point(raw).map_err(|e| {
            self.error(
                from,
                "step.reference",
                format!("#{id} is not a usable CARTESIAN_POINT: {e}"),
            )
        })?;
        Ok(mul(c, self.scale))
    }

    fn direction(&self, id: u64, from: u64) -> Res<Point3> {
        match &self.item(id, from, "DIRECTION")?.record {
            R::Direction { direction_ratios } if (2..=3).contains(&direction_ratios.len()) => {
                let mut d = [0.0; 3];
                d[..direction_ratios.len()].copy_from_slice(&direction_ratios[..]);
                normalise(d)
                    .ok_or_else(|| self.error(id, "geometry.invalid", "direction has zero length"))
            }
            _ => Err(self.error(
                from,
                "step.reference",
                format!("#{id} is not a DIRECTION of 2 or 3 ratios"),
            )),
        }
    }

    /// A VECTOR as `orientation * magnitude` (magnitude a length).
    fn vector(&self, id: u64, from: u64) -> Res<Point3> {
        match &self.item(id, from, "VECTOR")?.record {
            R::Vector {
                orientation,
                magnitude,
            } => {
                if !(magnitude.is_finite() && *magnitude > 0.0) {
                    return Err(self.error(
                        id,
                        "geometry.invalid",
                        format!("vector magnitude {magnitude} must be > 0"),
                    ));
                }
                Ok(mul(
                    self.direction(*orientation, id)?,
                    magnitude * self.scale,
                ))
            }
            _ => Err(self.error(from, "step.reference", format!("#{id} is not a VECTOR"))),
        }
    }

    /// An AXIS2_PLACEMENT_3D (ISO 10303-42 `build_axes`) or _2D (`build_2axes`, in z = 0).
    pub(super) fn frame(&self, id: u64, from: u64) -> Res<Frame> {
        let item = self.item(id, from, "AXIS2_PLACEMENT")?;
        let (location, frame) = match &item.record {
            R::Axis2Placement3d {
                location,
                axis,
                ref_direction,
            } => {
                let axis = axis.map(|a| self.direction(a, id)).transpose()?;
                let refd = ref_direction.map(|a| self.direction(a, id)).transpose()?;
                (*location, build_axes(axis, refd))
            }
            R::Axis2Placement2d {
                location,
                ref_direction,
            } => {
                // build_2axes: d = NVL(normalise(ref_direction), (1,0)), (d, (-d2, d1)).
                let d = match ref_direction {
                    Some(r) => self.direction(*r, id)?,
                    None => [1.0, 0.0, 0.0],
                };
                (
                    *location,
                    Some(Frame {
                        origin: [0.0; 3],
                        x: d,
                        y: [-d[1], d[0], 0.0],
                        z: [0.0, 0.0, 1.0],
                    }),
                )
            }
            _ => {
                return Err(self.error(
                    from,
                    "step.reference",
                    format!("#{id} is not an AXIS2_PLACEMENT_3D or _2D"),
                ));
            }
        };
        let mut frame = frame.ok_or_else(|| {
            self.error(
                id,
                "geometry.invalid",
                "ref_direction is parallel to axis (ISO 10303-42 build_axes is undefined)",
            )
        })?;
        frame.origin = self.point(location, id)?;
        Ok(frame)
    }

    fn positive(&self, id: u64, what: &str, v: f64) -> Res<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v * self.scale)
        } else {
            Err(self.error(id, "geometry.invalid", format!("{what} {v} must be > 0")))
        }
    }

    /// The ISO 10303-42 curve `#id` (following surface curves to their 3-D curve).
    pub(super) fn basis(&self, id: u64, from: u64, depth: usize) -> Res<Basis> {
        if depth > MAX_NESTING {
            return Err(self.error(
                from,
                "limit.nesting_depth",
                format!("curves nested deeper than {MAX_NESTING} levels at #{id}"),
            ));
        }
        let Some(item) = self.items.get(&id) else {
            return self.bspline_basis(id, from);
        };
        Ok(match &item.record {
            R::Line { pnt, dir } => Basis::Line {
                p: self.point(*pnt, id)?,
                d: self.vector(*dir, id)?,
            },
            R::Circle { position, radius } => {
                let f = self.frame(*position, id)?;
                let r = self.positive(id, "radius", *radius)?;
                Basis::Conic {
                    kind: ConicKind::Elliptic,
                    c: f.origin,
                    x: mul(f.x, r),
                    y: mul(f.y, r),
                    shape: Shape::CircularArc,
                }
            }
            R::Ellipse {
                position,
                semi_axis_1,
                semi_axis_2,
            } => {
                let f = self.frame(*position, id)?;
                Basis::Conic {
                    kind: ConicKind::Elliptic,
                    c: f.origin,
                    x: mul(f.x, self.positive(id, "semi_axis_1", *semi_axis_1)?),
                    y: mul(f.y, self.positive(id, "semi_axis_2", *semi_axis_2)?),
                    shape: Shape::EllipticArc,
                }
            }
            R::Hyperbola {
                position,
                semi_axis,
                semi_imag_axis,
            } => {
                let f = self.frame(*position, id)?;
                Basis::Conic {
                    kind: ConicKind::Hyperbolic,
                    c: f.origin,
                    x: mul(f.x, self.positive(id, "semi_axis", *semi_axis)?),
                    y: mul(f.y, self.positive(id, "semi_imag_axis", *semi_imag_axis)?),
                    shape: Shape::HyperbolicArc,
                }
            }
            R::Parabola {
                position,
                focal_dist,
            } => {
                let f = self.frame(*position, id)?;
                let a = if focal_dist.is_finite() && *focal_dist != 0.0 {
                    focal_dist * self.scale
                } else {
                    return Err(self.error(
                        id,
                        "geometry.invalid",
                        format!("focal_dist {focal_dist} must be non-zero"),
                    ));
                };
                Basis::Parabola {
                    v: f.origin,
                    x: mul(f.x, a),
                    y: mul(f.y, a),
                }
            }
            R::Polyline { points } => {
                // ISO 10303-42 polyline: segment i runs over parameters [i - 1, i].
                let pts = points
                    .iter()
                    .map(|&p| self.point(p, id))
                    .collect::<Res<Vec<_>>>()?;
                let params: Vec<f64> = (0..pts.len()).map(|i| i as f64).collect();
                Basis::Nurbs {
                    curve: polyline(&pts, &params).map_err(|e| self.geometry_error(id, e))?,
                    shape: Some(Shape::Polyline),
                    bspline: None,
                }
            }
            R::TrimmedCurve { .. } => {
                let (curve, shape, _) = self.trimmed(id, item, depth)?;
                Basis::Nurbs {
                    curve,
                    shape,
                    bspline: None,
                }
            }
            R::CompositeCurve { segments, .. } => Basis::Nurbs {
                curve: self.composite(id, segments, depth)?,
                shape: None,
                bspline: None,
            },
            R::SurfaceCurve { curve_3d, .. } => self.basis(*curve_3d, id, depth + 1)?,
            R::Offset { .. } => return Err(self.unsupported(id, item)),
            _ => {
                return Err(self.error(
                    from,
                    "step.reference",
                    format!("#{id} ({}) is not a curve", item.entity),
                ));
            }
        })
    }

    fn bspline_basis(&self, id: u64, from: u64) -> Res<Basis> {
        let raw = self
            .s
            .get(id)
            .ok_or_else(|| self.error(from, "step.reference", format!("#{id} is not defined")))?;
        match (self.bspline)(raw)? {
            Some(Entity {
                geometry: Geometry::Curve(curve),
                meta,
                ..
            }) => Ok(Basis::Nurbs {
                curve,
                shape: None,
                bspline: Some(Box::new(meta)),
            }),
            _ => Err(self.error(
                from,
                "step.reference",
                format!("#{from} references #{id}, which is not a usable curve"),
            )),
        }
    }

    /// A TRIMMED_CURVE (ISO 10303-42 4.4.21) as the exact piece of its basis curve, with
    /// the basis B-spline's metadata when the piece is that whole B-spline unchanged.
    fn trimmed(
        &self,
        id: u64,
        item: &Kept<'a>,
        depth: usize,
    ) -> Res<(NurbsCurve, Option<Shape>, Option<Meta>)> {
        let R::TrimmedCurve {
            basis_curve,
            trimming,
        } = &item.record
        else {
            return Err(self.error(id, "step.reference", "not a TRIMMED_CURVE"));
        };
        let Trimming {
            trim_1,
            trim_2,
            sense_agreement,
            master_representation,
        } = trimming.as_ref();
        let basis = self.basis(*basis_curve, id, depth + 1)?;
        let t1 = self.trim_value(id, &basis, trim_1, master_representation)?;
        let t2 = self.trim_value(id, &basis, trim_2, master_representation)?;
        let (from, to) = if *sense_agreement { (t1, t2) } else { (t2, t1) };
        let (a, b) = forward_range(from, to, basis.period()).ok_or_else(|| {
            self.error(
                id,
                "geometry.invalid",
                format!("trim values {t1} and {t2} do not bound a piece of the open basis curve #{basis_curve} in the sense given"),
            )
        })?;
        let mut curve = basis
            .bounded(a, b)
            .map_err(|e| self.geometry_error(id, e))?;
        if !sense_agreement {
            curve = curve.reverse().map_err(|e| self.geometry_error(id, e))?;
        }
        let meta = match &basis {
            Basis::Nurbs {
                curve: whole,
                bspline: Some(meta),
                ..
            } if *whole == curve => Some(meta.as_ref().clone()),
            _ => None,
        };
        Ok((curve, basis.shape(), meta))
    }

    /// One trim's value as an ISO parameter of the basis (radians for circles and ellipses):
    /// the parameter value when the master representation is PARAMETER or UNSPECIFIED (or
    /// when only a parameter is given), else the exact inverse of the point.
    fn trim_value(
        &self,
        id: u64,
        basis: &Basis,
        trim: &[TrimmingSelect],
        master: &str,
    ) -> Res<f64> {
        let param = trim.iter().find_map(|t| match t {
            TrimmingSelect::Parameter(v) => Some(*v),
            TrimmingSelect::Point(_) => None,
        });
        let point = trim.iter().find_map(|t| match t {
            TrimmingSelect::Point(p) => Some(*p),
            TrimmingSelect::Parameter(_) => None,
        });
        let from_point = |p: u64| -> Res<Option<f64>> {
            let q = self.point(p, id)?;
            Ok(basis.inverse(q))
        };
        let from_param = |v: f64| self.convert_param(curve_param(basis), v);
        match (master, param, point) {
            ("CARTESIAN", _, Some(p)) => {
                if let Some(t) = from_point(p)? {
                    return Ok(t);
                }
                param.map(from_param).ok_or_else(|| {
                    self.error(
                        id,
                        "geometry.unsupported",
                        format!("trim by point #{p} on a B-spline basis needs a parameter value (no exact inverse)"),
                    )
                    .not_carried()
                })
            }
            (_, Some(v), point) => {
                let t = from_param(v);
                // Both given and the parameter's point is not the trim point: writers
                // differ on parameter conventions (Open CASCADE writes a parabola's trims in
                // its own parameter, 2 f times ISO 10303-42's), a point is unambiguous. The
                // exact inverse of the point is used, and said.
                if let (Some(p), false) = (point, matches!(basis, Basis::Nurbs { .. })) {
                    let q = self.point(p, id)?;
                    let off = norm(sub(basis.point(t), q));
                    if let (true, Some(e)) = (off > 1e-7 * (1.0 + norm(q)), basis.inverse(q)) {
                        if let Ok(mut w) = self.warnings.lock() {
                            w.push(Diagnostic::warning(
                                "trim.parameter_mismatch",
                                format!("trim parameter {v} gives a point {off:e} away from trim point #{p}; the point's exact parameter {e} is used"),
                                self.location(id),
                            ));
                        }
                        return Ok(e);
                    }
                }
                // A parameter outside an open B-spline basis's domain cannot be a value of
                // its parameter (files that re-parameterised the basis but kept old trims);
                // a trim point at one of its ends is exact and used instead, and said.
                // Otherwise the value is clamped to the domain, and said.
                if let (Basis::Nurbs { curve, .. }, None) = (basis, basis.period()) {
                    let (a, b) = curve.domain();
                    let slack = 1e-9 * (b - a);
                    if t < a - slack || t > b + slack {
                        let (e, how) = match point.map(from_point).transpose()?.flatten() {
                            Some(e) => (e, format!("trim point #{} (the basis end at {e}) is used", point.unwrap_or_default())),
                            None => {
                                let e = t.clamp(a, b);
                                (e, format!("it is clamped to {e}"))
                            }
                        };
                        if let Ok(mut w) = self.warnings.lock() {
                            w.push(Diagnostic::warning(
                                "trim.parameter_outside",
                                format!("trim parameter {v} is outside the basis curve's domain [{a}, {b}]; {how}"),
                                self.location(id),
                            ));
                        }
                        return Ok(e);
                    }
                }
                Ok(t)
            }
            (_, None, Some(p)) => from_point(p)?.ok_or_else(|| {
                self.error(
                    id,
                    "geometry.unsupported",
                    format!("trim by point #{p} on a B-spline basis needs a parameter value (no exact inverse)"),
                )
                .not_carried()
            }),
            _ => Err(self.error(id, "geometry.invalid", "empty trim")),
        }
    }

    /// A COMPOSITE_CURVE (ISO 10303-42 4.4.22): the segments joined end to end, each in its
    /// `same_sense`, the first starting at parameter 0 and each next one continuing where
    /// the previous one ends. Segments of lower degree are elevated (A5.9), polynomial
    /// segments made rational with unit weights, so that all can be joined exactly.
    fn composite(&self, id: u64, segments: &[u64], depth: usize) -> Res<NurbsCurve> {
        let mut pieces = Vec::with_capacity(segments.len());
        for &seg in segments {
            let item = self.item(seg, id, "COMPOSITE_CURVE_SEGMENT")?;
            let R::CompositeCurveSegment {
                same_sense,
                parent_curve,
                ..
            } = item.record
            else {
                return Err(self.error(
                    id,
                    "step.reference",
                    format!("segment #{seg} is not a COMPOSITE_CURVE_SEGMENT"),
                ));
            };
            let basis = self.basis(parent_curve, seg, depth + 1)?;
            let (a, b) = basis.natural_range().ok_or_else(|| {
                self.error(
                    seg,
                    "geometry.invalid",
                    format!("parent curve #{parent_curve} is unbounded"),
                )
            })?;
            let mut c = basis
                .bounded(a, b)
                .map_err(|e| self.geometry_error(seg, e))?;
            if !same_sense {
                c = c.reverse().map_err(|e| self.geometry_error(seg, e))?;
            }
            pieces.push(c);
        }
        let degree = pieces.iter().map(NurbsCurve::degree).max().unwrap_or(1);
        let rational = pieces.iter().any(NurbsCurve::is_rational);
        let mut joined: Option<NurbsCurve> = None;
        for c in pieces {
            let mut c = if c.degree() < degree {
                c.elevate(degree - c.degree())
                    .map_err(|e| self.geometry_error(id, e))?
            } else {
                c
            };
            if rational && !c.is_rational() {
                let (p, k, pts, _, dim) = c.into_parts();
                let w = vec![1.0; pts.len()];
                c = NurbsCurve::with_dimension(p, k, pts, Some(w), dim)
                    .map_err(|e| self.geometry_error(id, e))?;
            }
            joined = Some(match joined {
                None => {
                    let (a, b) = c.domain();
                    c.reparameterize(0.0, b - a)
                        .map_err(|e| self.geometry_error(id, e))?
                }
                Some(prev) => {
                    let tol = super::closure_tolerance(prev.control_points())
                        .max(super::closure_tolerance(c.control_points()));
                    prev.join(&c, tol).map_err(|e| self.geometry_error(id, e))?
                }
            });
        }
        joined.ok_or_else(|| self.error(id, "geometry.invalid", "composite curve has no segments"))
    }

    /// The ISO 10303-42 surface `#id`.
    fn surface_basis(&self, id: u64, from: u64, depth: usize) -> Res<SurfaceBasis> {
        if depth > MAX_NESTING {
            return Err(self.error(
                from,
                "limit.nesting_depth",
                format!("surfaces nested deeper than {MAX_NESTING} levels at #{id}"),
            ));
        }
        let Some(item) = self.items.get(&id) else {
            let raw = self.s.get(id).ok_or_else(|| {
                self.error(from, "step.reference", format!("#{id} is not defined"))
            })?;
            return match (self.bspline)(raw)? {
                Some(Entity {
                    geometry: Geometry::Surface(s),
                    ..
                }) => Ok(SurfaceBasis::Nurbs(s)),
                _ => Err(self.error(
                    from,
                    "step.reference",
                    format!("#{from} references #{id}, which is not a usable surface"),
                )),
            };
        };
        Ok(match &item.record {
            R::Plane { position } => SurfaceBasis::Plane(self.frame(*position, id)?),
            R::CylindricalSurface { position, radius } => SurfaceBasis::Cylinder(
                self.frame(*position, id)?,
                self.positive(id, "radius", *radius)?,
            ),
            R::ConicalSurface {
                position,
                radius,
                semi_angle,
            } => {
                let r = radius * self.scale;
                if !(r.is_finite() && r >= 0.0) {
                    return Err(self.error(
                        id,
                        "geometry.invalid",
                        format!("radius {radius} must be >= 0"),
                    ));
                }
                SurfaceBasis::Cone(self.frame(*position, id)?, r, self.angle(*semi_angle))
            }
            R::SphericalSurface { position, radius } => SurfaceBasis::Sphere(
                self.frame(*position, id)?,
                self.positive(id, "radius", *radius)?,
            ),
            R::ToroidalSurface {
                position,
                major_radius,
                minor_radius,
                select_outer,
            } => {
                let big = self.positive(id, "major_radius", *major_radius)?;
                let small = self.positive(id, "minor_radius", *minor_radius)?;
                // ISO 10303-42 degenerate_toroidal_surface: with R < r the tube crosses the
                // axis where R + r cos v = 0; select_outer keeps |v| <= acos(-R/r) (the
                // outer, apple-shaped part), else the inner (lemon-shaped) part.
                let v = match select_outer {
                    Some(outer) if big < small => {
                        let c = (-big / small).acos();
                        if *outer { (-c, c) } else { (c, TAU - c) }
                    }
                    _ => (0.0, TAU),
                };
                SurfaceBasis::Torus(self.frame(*position, id)?, big, small, v)
            }
            R::SurfaceOfRevolution {
                swept_curve,
                axis_position,
            } => {
                let R::Axis1Placement { location, axis } =
                    self.item(*axis_position, id, "AXIS1_PLACEMENT")?.record
                else {
                    return Err(self.error(
                        id,
                        "step.reference",
                        format!("#{axis_position} is not an AXIS1_PLACEMENT"),
                    ));
                };
                let axis = match axis {
                    Some(a) => self.direction(a, *axis_position)?,
                    None => [0.0, 0.0, 1.0],
                };
                SurfaceBasis::Revolution {
                    profile: self.basis(*swept_curve, id, depth + 1)?,
                    point: self.point(location, *axis_position)?,
                    axis,
                }
            }
            R::SurfaceOfLinearExtrusion {
                swept_curve,
                extrusion_axis,
            } => SurfaceBasis::Extrusion {
                profile: self.basis(*swept_curve, id, depth + 1)?,
                d: self.vector(*extrusion_axis, id)?,
            },
            R::RectangularTrimmedSurface { .. } => {
                SurfaceBasis::Nurbs(self.rectangular_trimmed(id, item, depth)?.0)
            }
            R::Offset { .. } => return Err(self.unsupported(id, item)),
            _ => {
                return Err(self.error(
                    from,
                    "step.reference",
                    format!("#{id} ({}) is not a surface", item.entity),
                ));
            }
        })
    }

    /// A RECTANGULAR_TRIMMED_SURFACE (ISO 10303-42 4.4.50): the basis on `u1..u2 x v1..v2`
    /// (angles in the plane-angle unit, lengths in the length unit); `usense`/`vsense` false
    /// reverses that direction.
    fn rectangular_trimmed(
        &self,
        id: u64,
        item: &Kept<'a>,
        depth: usize,
    ) -> Res<(NurbsSurface, Option<Shape>)> {
        let R::RectangularTrimmedSurface {
            basis_surface,
            ref bounds,
        } = item.record
        else {
            return Err(self.error(id, "step.reference", "not a RECTANGULAR_TRIMMED_SURFACE"));
        };
        let RectangularTrim {
            u1,
            u2,
            v1,
            v2,
            usense,
            vsense,
        } = **bounds;
        let basis = self.surface_basis(basis_surface, id, depth + 1)?;
        let (ku, kv) = basis.units();
        let (pu, pv) = basis.periods();
        let range = |a: f64, b: f64, sense: bool, kind: Param, period: Option<f64>| {
            let (a, b) = (self.convert_param(kind, a), self.convert_param(kind, b));
            let (from, to) = if sense { (a, b) } else { (b, a) };
            forward_range(from, to, period).ok_or_else(|| {
                self.error(
                    id,
                    "geometry.invalid",
                    format!("trim range {a}..{b} is empty in the sense given"),
                )
            })
        };
        let ur = range(u1, u2, usense, ku, pu)?;
        let vr = range(v1, v2, vsense, kv, pv)?;
        // The reversals below change the parameterisation: no closed-form map is kept.
        let (mut s, _) = basis
            .build(ur, vr)
            .map_err(|e| self.geometry_error(id, e))?;
        if !usense {
            s = s.reverse_u().map_err(|e| self.geometry_error(id, e))?;
        }
        if !vsense {
            s = s.reverse_v().map_err(|e| self.geometry_error(id, e))?;
        }
        Ok((s, basis.shape()))
    }

    fn entity(
        &self,
        id: u64,
        label: Label,
        geometry: Geometry,
        shape: Option<Shape>,
        used_by: Vec<Label>,
        base: Option<Meta>,
    ) -> Placed {
        let mut meta = base.unwrap_or_default();
        let offset = self.s.get(id).map_or(0, |raw| raw.offset());
        let found = self.provenance(id);
        if found.name.is_some() {
            meta.name = found.name;
        }
        meta.shape = shape;
        meta.used_by = used_by;
        (
            offset,
            Entity {
                id: label,
                geometry,
                source: Source {
                    entity: found.entity,
                    line: found.line,
                },
                meta,
            },
        )
    }

    /// The line of instance `#id`, and the entity type as written and the name (when not
    /// empty) of item `#id`, read again from its instance (see [`Kept`]); an empty type and
    /// no name when `#id` is no item.
    pub(super) fn provenance(&self, id: u64) -> Provenance {
        let item = self.items.get(&id);
        // A plain item whose line was found when it was decoded: nothing to read again, not
        // even the index.
        if let Some(k) = item.filter(|k| k.plain && k.line > 0) {
            return Provenance {
                line: usize::try_from(k.line).ok(),
                entity: Cow::Borrowed(k.entity.name()),
                name: None,
            };
        }
        let Some(raw) = self.s.get(id) else {
            return Provenance::default();
        };
        let line = Some(self.s.line(raw.offset()));
        if item.is_none() {
            return Provenance {
                line,
                ..Provenance::default()
            };
        }
        // Decoded before, so read again (the decoders are pure functions of the text).
        let (entity, name) = match self.s.geometry_provenance(raw) {
            Ok(Some((entity, name))) => (
                entity,
                name.map(|n| n.decode_lossy().into_owned())
                    .filter(|n| !n.is_empty()),
            ),
            _ => Default::default(),
        };
        Provenance { line, entity, name }
    }
}

/// Where an item's instance is and what it is ([`Converter::provenance`]): empty and `None`
/// for an id that is not in the file.
#[derive(Debug, Default)]
pub(super) struct Provenance {
    /// The instance's 1-based line.
    pub line: Option<usize>,
    /// The entity type as written; empty when the id is no geometry item.
    pub entity: Cow<'static, str>,
    /// The name, when the item has one that is not empty.
    pub name: Option<String>,
}

/// An edge's curve after bounding: the NURBS, the curve instance it came from, and whether
/// that instance is a B-spline the reader's B-spline path converts on its own.
#[derive(Clone)]
pub(super) struct EdgeOut {
    pub curve: NurbsCurve,
    curve_id: u64,
    shape: Option<Shape>,
    bspline: bool,
    /// Start and end vertex are the same (the edge closes on itself).
    closed: bool,
    /// The [`Entity::id`] holding the curve (set by [`Converter::run`]).
    pub entity: Label,
    /// The part of `curve` the edge uses when it is not the whole curve (a B-spline whose
    /// vertices lie inside it).
    pub range: Option<(f64, f64)>,
}

/// Values by instance id, in the order added, found through a table of places. The
/// values (converted edges, entities of a few hundred bytes) move once, into the list: a
/// hash table of the values themselves moved them at every growth and probed across them,
/// a visible part of a large read.
pub(super) struct ByInstance<T> {
    list: Vec<(u64, T)>,
    /// Instance id -> index in `list`.
    at: HashMap<u64, usize>,
}

impl<T> Default for ByInstance<T> {
    fn default() -> Self {
        ByInstance {
            list: Vec::new(),
            at: HashMap::default(),
        }
    }
}

impl<T> ByInstance<T> {
    /// An empty one with room for `n` values (no growth, which moves every value, while
    /// at most `n` are added).
    pub(super) fn with_capacity(n: usize) -> Self {
        ByInstance {
            list: Vec::with_capacity(n),
            at: HashMap::with_capacity_and_hasher(n, Default::default()),
        }
    }

    /// Adds the value of `#id`; the first one added for an id stays.
    pub(super) fn push(&mut self, id: u64, value: T) {
        if let std::collections::hash_map::Entry::Vacant(v) = self.at.entry(id) {
            v.insert(self.list.len());
            self.list.push((id, value));
        }
    }

    pub(super) fn get(&self, id: u64) -> Option<&T> {
        let k = *self.at.get(&id)?;
        self.list.get(k).map(|(_, v)| v)
    }

    pub(super) fn get_mut(&mut self, id: u64) -> Option<&mut T> {
        let k = *self.at.get(&id)?;
        self.list.get_mut(k).map(|(_, v)| v)
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The values with their ids, in the order added.
    pub(super) fn into_list(self) -> Vec<(u64, T)> {
        self.list
    }
}

impl<'a> Converter<'_, '_, 'a> {
    /// The curve instance under an edge's geometry (through surface curves).
    fn edge_curve_id(&self, mut id: u64) -> u64 {
        for _ in 0..MAX_NESTING {
            match self.items.get(&id).map(|i| &i.record) {
                Some(R::SurfaceCurve { curve_3d, .. }) => id = *curve_3d,
                _ => break,
            }
        }
        id
    }

    /// An EDGE_CURVE's geometry bounded by its vertices (ISO 10303-42 5.4.6): lines and
    /// conics between the exact inverse parameters of the two vertex points, in the
    /// curve's own direction (the arc from start to end vertex when `same_sense`, from end
    /// to start otherwise); a closed conic whose edge starts and ends at one vertex is the
    /// whole conic from that vertex. Other curves (B-splines, polylines, trimmed and
    /// composite curves) are taken whole when their ends are the vertices, else between
    /// the vertices ([`Converter::nurbs_edge`]).
    fn edge(&self, id: u64) -> Res<EdgeOut> {
        let item = self.item(id, id, "EDGE_CURVE")?;
        let R::EdgeCurve {
            edge_start,
            edge_end,
            edge_geometry,
            same_sense,
        } = item.record
        else {
            return Err(self.error(id, "step.reference", "not an EDGE_CURVE"));
        };
        let curve_id = self.edge_curve_id(edge_geometry);
        let basis = self.basis(edge_geometry, id, 0)?;
        let closed = edge_start == edge_end;
        let shape = basis.shape();
        let vertex = |v: u64| -> Res<Point3> {
            match self.item(v, id, "VERTEX_POINT")?.record {
                R::VertexPoint { vertex_geometry } => self.point(vertex_geometry, v),
                _ => Err(self.error(id, "step.reference", format!("#{v} is not a VERTEX_POINT"))),
            }
        };
        if let Basis::Nurbs { curve, bspline, .. } = &basis {
            let (curve, range) = self.nurbs_edge(
                id,
                &basis,
                curve,
                (vertex(edge_start)?, vertex(edge_end)?),
                same_sense,
                closed,
            )?;
            return Ok(EdgeOut {
                curve,
                curve_id,
                shape,
                bspline: bspline.is_some(),
                closed,
                entity: Label::default(),
                range,
            });
        }
        let (p0, p1) = (vertex(edge_start)?, vertex(edge_end)?);
        let (t0, t1) = match (basis.inverse(p0), basis.inverse(p1)) {
            (Some(a), Some(b)) => (a, b),
            _ => return Err(self.error(id, "geometry.invalid", "no inverse for the edge curve")),
        };
        // The vertices must lie on the curve for the inverse to be the exact parameter.
        let size = norm(sub(p0, p1)).max(norm(basis.point(0.0)));
        let tol = self.vertex_tolerance(size);
        let mut diags = Vec::new();
        for (v, p, t) in [(edge_start, p0, t0), (edge_end, p1, t1)] {
            let off = norm(sub(basis.point(t), p));
            if off > tol {
                diags.push(format!("vertex #{v} is {off:e} off the curve"));
            }
        }
        if !diags.is_empty() {
            return Err(self.error(
                id,
                "geometry.invalid",
                format!("{}; the edge is not bounded exactly", diags.join(", ")),
            ));
        }
        let (from, to) = if same_sense { (t0, t1) } else { (t1, t0) };
        let range = if closed && basis.period().is_some() {
            Some((from, from + TAU))
        } else {
            forward_range(from, to, basis.period())
        };
        let (a, b) = range.ok_or_else(|| {
            self.error(
                id,
                "geometry.invalid",
                format!("vertices at parameters {t0} and {t1} do not bound the open curve in the sense given"),
            )
        })?;
        Ok(EdgeOut {
            curve: basis
                .bounded(a, b)
                .map_err(|e| self.geometry_error(id, e))?,
            curve_id,
            shape,
            bspline: false,
            closed,
            entity: Label::default(),
            range: None,
        })
    }

    /// An edge over a curve that is a NURBS already (B-spline, polyline, trimmed or
    /// composite curve): the whole curve when its ends are the vertices (in the sense of
    /// the edge), else the range between the vertices' parameters on it (point inversion,
    /// NURBS Book section 6.1; the vertices must lie on the curve within
    /// [`Converter::vertex_tolerance`]),
    /// in the curve's own direction as for conics: the whole curve with that range when it
    /// lies in the curve's domain, else (a range over the seam of a closed curve) the piece.
    fn nurbs_edge(
        &self,
        id: u64,
        basis: &Basis,
        curve: &NurbsCurve,
        (p0, p1): (Point3, Point3),
        same_sense: bool,
        closed: bool,
    ) -> Res<(NurbsCurve, Option<(f64, f64)>)> {
        let (from, to) = if same_sense { (p0, p1) } else { (p1, p0) };
        let (a, b) = curve.domain();
        let tol = self.vertex_tolerance(bounding_box_diagonal(curve.control_points()));
        let near = |p: Point3, q: Point3| norm(sub(p, q)) <= tol;
        if near(curve.point_at_unchecked(a), from) && near(curve.point_at_unchecked(b), to) {
            return Ok((curve.clone(), None));
        }
        let at = |p: Point3| {
            invert_curve(curve, p)
                .filter(|(_, d)| *d <= tol)
                .map(|(t, _)| t)
                .ok_or_else(|| {
                    self.error(
                        id,
                        "geometry.invalid",
                        format!("a vertex of the edge is not on its curve (tolerance {tol:e})"),
                    )
                })
        };
        let (ta, tb) = (at(from)?, at(to)?);
        let range = match basis.period() {
            Some(p) if closed => Some((ta, ta + p)),
            period => forward_range(ta, tb, period),
        };
        let (x, y) = range.ok_or_else(|| {
            self.error(
                id,
                "geometry.invalid",
                format!(
                    "vertices at parameters {ta} and {tb} do not bound the curve in the sense given"
                ),
            )
        })?;
        if a <= x && y <= b {
            return Ok((curve.clone(), Some((x, y))));
        }
        let piece = basis
            .bounded(x, y)
            .map_err(|e| self.geometry_error(id, e))?;
        Ok((piece, None))
    }

    /// The edges of a face (all its bounds, in order; a seam appears twice) and the points
    /// of its VERTEX_LOOPs (a cone's apex, a sphere's pole: ISO 10303-42 clause 5.4.13).
    fn face_edges(&self, face: u64) -> Res<(Vec<u64>, Vec<Point3>)> {
        let Some(R::FaceSurface { bounds, .. }) = self.items.get(&face).map(|i| &i.record) else {
            return Err(self.error(face, "step.reference", "not a FACE_SURFACE"));
        };
        let mut edges = Vec::new();
        let mut points = Vec::new();
        for &b in bounds {
            let R::FaceBound { bound, .. } = self.item(b, face, "FACE_BOUND")?.record else {
                return Err(self.error(
                    face,
                    "step.reference",
                    format!("#{b} is not a FACE_BOUND"),
                ));
            };
            // A VERTEX_LOOP (a single point, e.g. a sphere's pole) adds no edge, only its
            // point.
            let edge_list = match self.items.get(&bound).map(|i| &i.record) {
                Some(R::EdgeLoop { edge_list }) => edge_list,
                Some(R::VertexLoop { loop_vertex }) => {
                    match self.item(*loop_vertex, bound, "VERTEX_POINT")?.record {
                        R::VertexPoint { vertex_geometry } => {
                            points.push(self.point(vertex_geometry, *loop_vertex)?);
                        }
                        _ => {
                            return Err(self.error(
                                bound,
                                "step.reference",
                                format!("#{loop_vertex} is not a VERTEX_POINT"),
                            ));
                        }
                    }
                    continue;
                }
                _ => continue,
            };
            for &oe in edge_list {
                match self.item(oe, bound, "ORIENTED_EDGE")?.record {
                    R::OrientedEdge { edge_element, .. } => edges.push(edge_element),
                    _ => {
                        return Err(self.error(
                            bound,
                            "step.reference",
                            format!("#{oe} is not an ORIENTED_EDGE"),
                        ));
                    }
                }
            }
        }
        Ok((edges, points))
    }
}

/// The smallest angular interval holding `angles` (radians, any representatives): the
/// complement of the largest gap between neighbours on the circle.
fn angular_extent(mut angles: Vec<f64>) -> Option<(f64, f64)> {
    for a in &mut angles {
        *a = a.rem_euclid(TAU);
    }
    angles.sort_by(f64::total_cmp);
    let (first, last) = (*angles.first()?, *angles.last()?);
    let mut gap = first + TAU - last;
    let mut start = first;
    for w in angles.windows(2) {
        if w[1] - w[0] > gap {
            gap = w[1] - w[0];
            start = w[1];
        }
    }
    Some((start, start + TAU - gap))
}

/// Parameter box of a surface's faces from the poles of their edge curves, under the exact
/// inverse of the surface's parameterisation; `None` in a direction the poles do not
/// bound (the caller keeps the natural range there).
///
/// Why the box contains the faces: each edge curve lies in the convex hull of its poles
/// (NURBS Book P4.x, convex hull property, weights > 0). The plane coordinates and the
/// axial coordinate of a cylinder or cone are affine functions of the point, so their
/// extreme values over a convex hull are taken at poles. The angle about an axis of a point
/// of a convex set that does not reach the axis lies within the angular span of the set's
/// vertices; the edge curves here are conic arcs of at most 90 degrees per segment and lines,
/// whose control polygons sweep monotonically, so the span of the poles holds the edges.
/// A face whose edges go all the way round (a closed edge about the axis, or a seam used
/// twice) takes the full turn.
fn face_box(basis: &SurfaceBasis, poles: &[Point3], full_turn: bool, sizes: f64) -> Box2 {
    let span = |f: &dyn Fn(Point3) -> f64| -> Option<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for &p in poles {
            let v = f(p);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        (lo < hi).then_some((lo, hi))
    };
    let around = |o: Point3, x: Point3, y: Point3, z: Point3| -> Option<(f64, f64)> {
        if full_turn {
            return Some((0.0, TAU));
        }
        let angles: Vec<f64> = poles
            .iter()
            .filter_map(|&p| {
                let r = sub(p, o);
                let radial = sub(r, mul(z, dot(r, z)));
                (norm(radial) > sizes * 1e-9).then(|| dot(r, y).atan2(dot(r, x)))
            })
            .collect();
        angular_extent(angles)
    };
    match basis {
        SurfaceBasis::Plane(f) => (
            span(&|p| dot(sub(p, f.origin), f.x)),
            span(&|p| dot(sub(p, f.origin), f.y)),
        ),
        SurfaceBasis::Cylinder(f, _) | SurfaceBasis::Cone(f, _, _) => (
            around(f.origin, f.x, f.y, f.z),
            span(&|p| dot(sub(p, f.origin), f.z)),
        ),
        SurfaceBasis::Revolution {
            profile,
            point,
            axis,
        } => {
            // The revolution's u = 0 is the profile itself: angles are measured from the
            // radial direction of the profile's first pole off the axis.
            let q = match profile {
                Basis::Nurbs { curve, .. } => curve.control_points().to_vec(),
                other => match other
                    .natural_range()
                    .and_then(|(a, b)| other.bounded(a, b).ok())
                {
                    Some(c) => c.control_points().to_vec(),
                    None => return (None, None),
                },
            };
            let x = q.iter().find_map(|&p| {
                let r = sub(p, *point);
                let radial = sub(r, mul(*axis, dot(r, *axis)));
                (norm(radial) > sizes * 1e-9)
                    .then(|| normalise(radial))
                    .flatten()
            });
            let Some(x) = x else { return (None, None) };
            let y = cross(*axis, x);
            (around(*point, x, y, *axis), None)
        }
        SurfaceBasis::Extrusion { profile, d } => {
            let q: Vec<Point3> = match profile {
                Basis::Nurbs { curve, .. } => curve.control_points().to_vec(),
                other => match other
                    .natural_range()
                    .and_then(|(a, b)| other.bounded(a, b).ok())
                {
                    Some(c) => c.control_points().to_vec(),
                    None => return (None, None),
                },
            };
            let dd = dot(*d, *d);
            let (pl, ph) = match span(&|p| dot(p, *d)) {
                Some(s) => s,
                None => return (None, None),
            };
            let (ql, qh) = q
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &p| {
                    let v = dot(p, *d);
                    (l.min(v), h.max(v))
                });
            (None, Some(((pl - qh) / dd, (ph - ql) / dd)))
        }
        _ => (None, None),
    }
}

impl<'a> Converter<'_, '_, 'a> {
    /// Converts every curve and surface item of the file into entities (see the module
    /// documentation for what is emitted where). The entities have room for `extra` more
    /// (the B-splines the reader adds after them).
    pub(super) fn run(&self, extra: usize) -> Output {
        use rayon::prelude::*;
        let mut out = Output::default();
        // Uses: which items are parts of other ones, a flag per item by its position in
        // `items` (ids that are no item are parts of nothing converted here).
        let mut consumed = vec![false; self.items.len()];
        let mut consume = |id: u64| {
            if let Some(c) = self.items.position(id).and_then(|k| consumed.get_mut(k)) {
                *c = true;
            }
        };
        // (surface, face) of every FACE_SURFACE, grouped by surface after the pass.
        let mut face_pairs: Vec<(u64, u64)> = Vec::new();
        let mut pcurve_items: Vec<u64> = Vec::new();
        let mut edges: Vec<u64> = Vec::new();
        // A curve or surface built on itself (directly or through others) would be
        // consumed and never converted: such reference cycles are reported (the ones through
        // trimmed, composite and rectangular trimmed entities, followed by the scanner's
        // iterative search; a surface curve on itself is a self-reference, converted and
        // refused by the nesting limit). The same pass over the items (each is a pass over
        // the read's largest structure) lists those and the curves and surfaces that may
        // stand alone, with their positions (converted below unless used by others) and
        // whether they are built on themselves.
        let mut builders: Vec<u64> = Vec::new();
        let mut alone: Vec<(usize, u64, bool)> = Vec::new();
        // The points read below ([`Points`]), and the curves of edges (whose lines' points
        // are too).
        let mut points: Vec<u64> = Vec::new();
        let mut edge_curves: Vec<u64> = Vec::new();
        for (k, (id, item)) in self.items.iter().enumerate() {
            let record = &item.record;
            match record {
                R::VertexPoint { vertex_geometry: p }
                | R::Axis2Placement3d { location: p, .. }
                | R::Axis1Placement { location: p, .. } => points.push(*p),
                R::SurfaceCurve { curve_3d: c, .. }
                | R::EdgeCurve {
                    edge_geometry: c, ..
                } => {
                    edge_curves.push(*c);
                }
                _ => {}
            }
            if matches!(
                record,
                R::TrimmedCurve { .. }
                    | R::CompositeCurve { .. }
                    | R::CompositeCurveSegment { .. }
                    | R::RectangularTrimmedSurface { .. }
            ) {
                builders.push(id);
            }
            if stands_alone(record) {
                let on_itself = matches!(
                    record,
                    R::TrimmedCurve { basis_curve: b, .. } | R::SurfaceCurve { curve_3d: b, .. } if *b == id
                );
                alone.push((k, id, on_itself));
            }
            match record {
                R::TrimmedCurve { basis_curve, .. } => {
                    consume(*basis_curve);
                    out.consumed_bsplines.insert(*basis_curve);
                }
                R::CompositeCurveSegment { parent_curve, .. } => {
                    consume(*parent_curve);
                    out.consumed_bsplines.insert(*parent_curve);
                }
                R::SurfaceCurve { curve_3d, .. } => {
                    consume(*curve_3d);
                }
                R::EdgeCurve { edge_geometry, .. } => {
                    consume(*edge_geometry);
                    edges.push(id);
                }
                R::SurfaceOfRevolution { swept_curve, .. }
                | R::SurfaceOfLinearExtrusion { swept_curve, .. } => {
                    consume(*swept_curve);
                    out.consumed_bsplines.insert(*swept_curve);
                }
                R::RectangularTrimmedSurface { basis_surface, .. } => {
                    consume(*basis_surface);
                    out.consumed_bsplines.insert(*basis_surface);
                }
                R::Offset { basis } => {
                    consume(*basis);
                }
                R::DefinitionalRepresentation { items, .. } => {
                    for i in items {
                        consume(*i);
                        if self.items.contains_key(i) {
                            pcurve_items.push(*i);
                        }
                    }
                }
                R::FaceSurface { face_geometry, .. } => {
                    consume(*face_geometry);
                    face_pairs.push((*face_geometry, id));
                }
                _ => {}
            }
        }
        points.extend(edge_curves.iter().filter_map(|c| match self.items.get(c) {
            Some(Kept {
                record: R::Line { pnt, .. },
                ..
            }) => Some(*pnt),
            _ => None,
        }));
        drop(edge_curves);
        // Set once, here, before any point is read (unless given: `with_points`).
        if self.points.get().is_none() {
            let _ = self.points.set(Points::read(self.s, points));
        }
        let faces_of = FacesOf::new(face_pairs);
        let jobs: Vec<u64> = alone
            .into_iter()
            .filter(|&(k, _, on_itself)| on_itself || !consumed.get(k).copied().unwrap_or(false))
            .map(|(_, id, _)| id)
            .collect();
        drop(consumed);
        for e in self.s.find_cycles(builders) {
            out.diagnostics.push(Diagnostic::error(
                "step.reference_cycle",
                e.kind.to_string(),
                Location {
                    line: Some(e.line),
                    column: Some(e.column),
                    entity: e.entity.map(|e| super::instance_label(e).into()),
                    ..Location::default()
                },
            ));
        }
        // B-splines are consumed only where this module builds them into something else.
        out.consumed_bsplines
            .retain(|id| !self.items.contains_key(id) && self.s.get(*id).is_some());

        // Edges, in parallel (each independent), kept for the faces' boxes.
        let edge_results: Vec<(u64, Res<EdgeOut>)> =
            edges.par_iter().map(|&e| (e, self.edge(e))).collect();
        // Room for everything this run may add (an entity per edge, free item and face
        // surface, and `extra` more for the caller), so that no growth copies the entities
        // (a few hundred bytes each) or rehashes.
        out.entities
            .reserve_exact(edges.len() + jobs.len() + faces_of.len() + extra);
        out.quadric_maps.reserve(faces_of.len());
        let mut edge_list: ByInstance<EdgeOut> = ByInstance::with_capacity(edges.len());
        let mut uses: HashMap<u64, usize> =
            HashMap::with_capacity_and_hasher(edges.len(), Default::default());
        for (e, r) in edge_results {
            match r {
                Ok(mut o) => {
                    o.entity = super::instance_label(o.curve_id);
                    if !o.bspline {
                        let n = uses.entry(o.curve_id).or_insert(0);
                        *n += 1;
                        let label = if *n == 1 {
                            super::instance_label(o.curve_id)
                        } else {
                            compact_str::format_compact!("#{}@#{e}", o.curve_id)
                        };
                        o.entity.clone_from(&label);
                        out.entities.push(self.entity(
                            o.curve_id,
                            label,
                            Geometry::Curve(o.curve.clone()),
                            o.shape,
                            vec![super::instance_label(e)],
                            None,
                        ));
                    }
                    edge_list.push(e, o);
                }
                Err(d) => out.diagnostics.push(d),
            }
        }

        // Free-standing curves and every surface, in parallel.
        // Only what produced something is kept: most items are parts of others (points,
        // placements, topology), and a slot for each would be the read's peak of memory.
        let results: Vec<(Option<Placed>, Option<Diagnostic>)> = jobs
            .par_iter()
            .filter_map(|&id| match self.free_item(id, &faces_of) {
                (None, None) => None,
                found => Some(found),
            })
            .collect();
        for (e, d) in results {
            out.entities.extend(e);
            out.diagnostics.extend(d);
        }
        // Surfaces used by faces are consumed above but converted here, bounded by them.
        let results: Vec<(u64, Res<Option<FaceSurface>>)> = faces_of
            .surfaces
            .par_iter()
            .enumerate()
            .map(|(k, &sid)| (sid, self.face_surface(sid, faces_of.faces(k), &edge_list)))
            .collect();
        for (sid, r) in results {
            match r {
                Ok(Some((e, map))) => {
                    out.entities.push(e);
                    out.quadric_maps.extend(map.map(|m| (sid, m)));
                }
                Ok(None) => {}
                Err(d) => out.diagnostics.push(d),
            }
        }
        if let Ok(mut w) = self.warnings.lock() {
            out.diagnostics.append(&mut w);
        }
        out.edges = edge_list.into_list();
        out.edge_items = edges;
        // Parameter-space curves of analytic type are not converted: said once when the
        // topology is not read (see `Output::analytic_pcurves`).
        let analytic: Vec<u64> = pcurve_items
            .iter()
            .copied()
            .filter(|i| {
                !matches!(
                    self.items.get(i).map(|x| &x.record),
                    Some(R::Axis2Placement2d { .. } | R::Axis2Placement3d { .. })
                )
            })
            .collect();
        if let Some(&first) = analytic.first() {
            let list: Vec<String> = analytic
                .iter()
                .take(8)
                .map(|&i| super::instance_label(i).into())
                .collect();
            out.analytic_pcurves = Some(Diagnostic::warning(
                "pcurve.not_converted",
                format!(
                    "{} parameter-space curve(s) of PCURVEs are lines or conics in a surface's parameter plane ({}{}); they are not represented (the 3-D edge curves are)",
                    analytic.len(),
                    list.join(", "),
                    if analytic.len() > 8 { ", ..." } else { "" }
                ),
                self.location(first),
            )
            .not_carried());
        }
        out
    }

    /// A curve or surface item that nothing else uses.
    fn free_item(&self, id: u64, faces_of: &FacesOf) -> (Option<Placed>, Option<Diagnostic>) {
        let Some(item) = self.items.get(&id).filter(|i| stands_alone(&i.record)) else {
            return (None, None);
        };
        // Most items produce nothing here (they are parts of others): the label is made
        // only for what is kept.
        let label = || super::instance_label(id);
        let unbounded = |what: &str| {
            Diagnostic::warning(
                "geometry.unbounded",
                format!(
                    "{what} #{id} is unbounded and nothing in the file bounds it (no trim, edge or face uses it); it is not represented"
                ),
                self.location(id),
            )
            .not_carried()
        };
        match &item.record {
            R::Line { .. } | R::Hyperbola { .. } | R::Parabola { .. } => {
                (None, Some(unbounded(item.entity.name())))
            }
            R::TrimmedCurve { .. } => match self.trimmed(id, item, 0) {
                Ok((c, shape, meta)) => (
                    Some(self.entity(id, label(), Geometry::Curve(c), shape, Vec::new(), meta)),
                    None,
                ),
                Err(d) => (None, Some(d)),
            },
            R::Circle { .. }
            | R::Ellipse { .. }
            | R::Polyline { .. }
            | R::CompositeCurve { .. }
            | R::SurfaceCurve { .. } => {
                let b = match self.basis(id, id, 0) {
                    Ok(b) => b,
                    Err(d) => return (None, Some(d)),
                };
                let shape = b.shape();
                let curve = match b {
                    Basis::Nurbs {
                        bspline: Some(_), ..
                    } => return (None, None),
                    Basis::Nurbs { curve, .. } => Ok(curve),
                    other => match other.natural_range() {
                        Some((a, c)) => other.bounded(a, c).map_err(|e| self.geometry_error(id, e)),
                        None => return (None, Some(unbounded(item.entity.name()))),
                    },
                };
                match curve {
                    Ok(c) => (
                        Some(self.entity(id, label(), Geometry::Curve(c), shape, Vec::new(), None)),
                        None,
                    ),
                    Err(d) => (None, Some(d)),
                }
            }
            R::Plane { .. }
            | R::CylindricalSurface { .. }
            | R::ConicalSurface { .. }
            | R::SphericalSurface { .. }
            | R::ToroidalSurface { .. }
            | R::SurfaceOfRevolution { .. }
            | R::SurfaceOfLinearExtrusion { .. }
            | R::RectangularTrimmedSurface { .. } => {
                if faces_of.contains(id) {
                    return (None, None);
                }
                let r = if let R::RectangularTrimmedSurface { .. } = item.record {
                    self.rectangular_trimmed(id, item, 0)
                } else {
                    self.surface_basis(id, id, 0).and_then(|b| {
                        let (u, v) = b.natural();
                        match (u, v) {
                            (Some(u), Some(v)) => b
                                .build(u, v)
                                .map(|(s, _)| (s, b.shape()))
                                .map_err(|e| self.geometry_error(id, e)),
                            _ => Err(unbounded(item.entity.name())),
                        }
                    })
                };
                match r {
                    Ok((s, shape)) => (
                        Some(self.entity(
                            id,
                            label(),
                            Geometry::Surface(s),
                            shape,
                            Vec::new(),
                            None,
                        )),
                        None,
                    ),
                    Err(d) => (None, Some(d)),
                }
            }
            R::Offset { .. } => (None, Some(self.unsupported(id, item))),
            _ => (None, None),
        }
    }

    /// A surface used by faces: bounded in each unbounded (or angular) direction by the
    /// parameter box of the faces' edges ([`face_box`]), with the closed-form inverse of
    /// its parameterisation when it is a quadric.
    fn face_surface(
        &self,
        id: u64,
        faces: &[u64],
        edges: &ByInstance<EdgeOut>,
    ) -> Res<Option<FaceSurface>> {
        // A B-spline surface: the reader's B-spline path converts it (and reports what is
        // wrong with it); decoding it here too would only find that out.
        if !self.items.contains_key(&id)
            && self
                .s
                .get(id)
                .is_some_and(|raw| names_bspline_surface(self.s.text, raw))
        {
            return Ok(None);
        }
        let basis = self.surface_basis(id, id, 0)?;
        if let SurfaceBasis::Nurbs(_) = basis {
            if !matches!(
                self.items.get(&id).map(|i| &i.record),
                Some(R::RectangularTrimmedSurface { .. })
            ) {
                // A B-spline surface: the reader's B-spline path converts it.
                return Ok(None);
            }
        }
        let mut poles: Vec<Point3> = Vec::new();
        let mut full_turn = false;
        let mut seen: HashSet<u64> = HashSet::default();
        for &f in faces {
            let (face_edges, apexes) = self.face_edges(f)?;
            // The points of its VERTEX_LOOPs bound the face too (a cone's apex: the axial
            // extent; on the axis they take no part in the angular span).
            poles.extend_from_slice(&apexes);
            for e in face_edges {
                let Some(o) = edges.get(e) else {
                    return Err(self.error(
                        f,
                        "geometry.invalid",
                        format!("edge #{e} of face #{f} could not be converted, so the face's surface #{id} cannot be bounded"),
                    ));
                };
                // A seam (the same edge twice in one face) or an edge closed on itself
                // goes all the way round.
                if !seen.insert(e) || o.closed {
                    full_turn = true;
                }
                poles.extend_from_slice(o.curve.control_points());
            }
        }
        let size = bounding_box_diagonal(&poles);
        let (nu, nv) = basis.natural();
        let (bu, bv) = face_box(&basis, &poles, full_turn, size);
        let angular_u = matches!(
            basis,
            SurfaceBasis::Cylinder(..) | SurfaceBasis::Cone(..) | SurfaceBasis::Revolution { .. }
        );
        let u = if angular_u { bu.or(nu) } else { nu.or(bu) };
        let v = nv.or(bv);
        let (Some(u), Some(v)) = (u, v) else {
            return Err(Diagnostic::warning(
                "geometry.unbounded",
                format!(
                    "surface #{id} is unbounded and its faces' edges do not bound it; it is not represented"
                ),
                self.location(id),
            )
            .not_carried());
        };
        let trimmed = self
            .items
            .get(&id)
            .filter(|item| matches!(item.record, R::RectangularTrimmedSurface { .. }));
        let (surface, map) = if let Some(item) = trimmed {
            (self.rectangular_trimmed(id, item, 0)?.0, None)
        } else {
            basis.build(u, v).map_err(|e| self.geometry_error(id, e))?
        };
        let placed = self.entity(
            id,
            super::instance_label(id),
            Geometry::Surface(surface),
            basis.shape(),
            faces.iter().map(|&f| super::instance_label(f)).collect(),
            None,
        );
        Ok(Some((placed, map)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nurbsx_parsers::step::geometry::Ratios;

    /// An item of the given id (a DIRECTION whose ratio is the id, to tell them apart).
    fn item(id: u64) -> (u64, Kept<'static>) {
        let item = Kept {
            entity: GeometryEntity::named("DIRECTION").expect("a geometry entity"),
            record: R::Direction {
                direction_ratios: Ratios::new(&[id as f64]).expect("one ratio"),
            },
            plain: true,
            line: 0,
        };
        (id, item)
    }

    /// The items are found by id whether the ids are dense (a slot table) or sparse (binary
    /// search), given in any order; ids that are not items, 0 and the largest u64
    /// included, are not found.
    #[test]
    fn items_are_found_by_id_dense_or_sparse() {
        let dense: Vec<u64> = (1..=3000).rev().filter(|i| i % 3 != 0).collect();
        let sparse: Vec<u64> = (1..=3000).map(|j| j << 24).chain([u64::MAX - 1]).collect();
        for ids in [dense, sparse] {
            let items = Items::new(ids.iter().map(|&i| item(i)).collect());
            assert_eq!(items.is_empty(), ids.is_empty());
            let mut sorted = ids.clone();
            sorted.sort_unstable();
            assert_eq!(items.iter().map(|(id, _)| id).collect::<Vec<_>>(), sorted);
            for &id in &ids {
                let found = items.get(&id).map(|i| &i.record);
                assert_eq!(
                    found,
                    Some(&R::Direction {
                        direction_ratios: Ratios::new(&[id as f64]).expect("one ratio")
                    })
                );
                for other in [id.wrapping_add(1), id.wrapping_sub(1)] {
                    assert_eq!(items.contains_key(&other), ids.contains(&other));
                }
            }
            for absent in [0, u64::MAX, 3, 1 << 23] {
                assert!(!items.contains_key(&absent));
            }
            // After a retain, the kept ones (every id whose quotient by 2 or by 2^25 is odd)
            // are found with their records, the others are not.
            let mut items = items;
            let kept = |id: u64| (id / 2) % 2 == 1 || (id >> 25) % 2 == 1;
            items.retain(|id, _| kept(id));
            let expect: Vec<u64> = sorted.iter().copied().filter(|&i| kept(i)).collect();
            assert!(!expect.is_empty() && expect.len() < sorted.len());
            assert_eq!(items.iter().map(|(id, _)| id).collect::<Vec<_>>(), expect);
            for &id in &ids {
                let found = items.get(&id).map(|i| &i.record);
                let record = R::Direction {
                    direction_ratios: Ratios::new(&[id as f64]).expect("one ratio"),
                };
                assert_eq!(found, kept(id).then_some(&record), "#{id}");
            }
        }
        // Dense ids of which a few far apart are kept: the table is cut after the last.
        let mut items = Items::new((1..=3000).map(item).collect());
        items.retain(|id, _| id == 1 || (2000..2010).contains(&id));
        assert_eq!(items.slots.len(), 2010);
        for id in 0..=3001 {
            assert_eq!(
                items.contains_key(&id),
                id == 1 || (2000..2010).contains(&id)
            );
        }
        assert!(Items::new(Vec::new()).is_empty());
    }

    /// Gathering ids in file order (ascending, with a repeated id and gaps, some refused)
    /// in its one pass gives the items and the slot table that sorting the same items and
    /// building the table from them give; the first of a repeated id stays.
    #[test]
    fn gathering_in_order_equals_sorting() {
        let ids: Vec<u64> = vec![2, 3, 3, 7, 8, 20, 21, 22, 40, 41, 90];
        let refused = |id: u64| id == 8 || id == 40;
        let list: Vec<(u64, (u64, usize))> = ids
            .iter()
            .enumerate()
            .map(|(k, &id)| (id, (id, k)))
            .collect();
        // Each item records its position in the list (the ratio), to tell repeats apart.
        let make = |(id, k): (u64, usize)| {
            (!refused(id)).then(|| Kept {
                entity: GeometryEntity::named("DIRECTION").expect("a geometry entity"),
                record: R::Direction {
                    direction_ratios: Ratios::new(&[k as f64]).expect("one ratio"),
                },
                plain: true,
                line: 0,
            })
        };
        // The sorting construction: the items made, sorted stably by id, the first of a
        // repeated id kept, and their table.
        let mut sorted: Vec<(u64, Kept<'static>)> = list
            .iter()
            .filter_map(|&(id, x)| make(x).map(|k| (id, k)))
            .collect();
        sorted.sort_by_key(|(id, _)| *id);
        sorted.dedup_by_key(|(id, _)| *id);
        let gathered = Items::gather(list, make);
        assert!(!gathered.slots.is_empty());
        assert_eq!(gathered.slots, Items::slots(&sorted));
        assert_eq!(gathered.entries, sorted);
        let expect: Vec<u64> = vec![2, 3, 7, 20, 21, 22, 41, 90];
        assert_eq!(
            gathered.iter().map(|(id, _)| id).collect::<Vec<_>>(),
            expect
        );
        // #3 is the first of the two (list position 1).
        assert_eq!(
            gathered.get(&3).map(|i| &i.record),
            Some(&R::Direction {
                direction_ratios: Ratios::new(&[1.0]).expect("one ratio")
            })
        );
        for id in 0..=100 {
            assert_eq!(gathered.contains_key(&id), expect.contains(&id), "#{id}");
        }
    }

    /// An item with its id stays within 64 bytes: the items are the read's largest
    /// structure, and 8 bytes more per item put the 100 MB B-rep's peak above 3x the file.
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn an_item_with_its_id_fits_64_bytes() {
        assert!(std::mem::size_of::<(u64, Kept<'static>)>() <= 64);
    }

    /// Ids a power of two apart (`#16777216`, `#33554432`, ...) land in different buckets:
    /// a plain multiplicative hash gives them all the same low bits (one bucket, quadratic
    /// probing: 40 000 such CIRCLEs took 10x as long as consecutive ids).
    /// Over 512 seeds, not just this process's: foldhash's `fast` variant put them in a few
    /// hundred buckets for about one process seed in sixteen (a flaky failure of this test),
    /// its `quality` variant (one more folded multiply) does not.
    #[test]
    fn chosen_ids_do_not_share_buckets() {
        use std::hash::BuildHasher;
        fn distinct_low_bits(hasher: &impl BuildHasher) -> usize {
            (1..=4096u64)
                .map(|j| hasher.hash_one(j << 24) & 0xFFFF)
                .collect::<HashSet<u64>>()
                .len()
        }
        // 4096 random 16-bit values have about 3971 distinct ones.
        let here = distinct_low_bits(HashMap::<u64, ()>::default().hasher());
        assert!(here > 3800, "{here} distinct");
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..512 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let shared: &'static foldhash::SharedSeed =
                Box::leak(Box::new(foldhash::SharedSeed::from_u64(state)));
            let seeded = foldhash::quality::SeedableRandomState::with_seed(state >> 7, shared);
            let n = distinct_low_bits(&seeded);
            assert!(n > 3800, "{n} distinct with seed {state}");
        }
    }

    #[test]
    fn build_axes_follows_iso_10303_42() {
        // Defaults: z = (0,0,1), x = (1,0,0), y = (0,1,0).
        let f = build_axes(None, None).unwrap();
        assert_eq!((f.x, f.y, f.z), ([1., 0., 0.], [0., 1., 0.], [0., 0., 1.]));
        // z along x: first_proj_axis takes (0,1,0).
        let f = build_axes(Some([2.0, 0.0, 0.0]), None).unwrap();
        assert_eq!((f.x, f.y, f.z), ([0., 1., 0.], [0., 0., 1.], [1., 0., 0.]));
        // A ref_direction not normal to z is projected: (1,0,1) with z = (0,0,1) -> (1,0,0).
        let f = build_axes(Some([0.0, 0.0, 1.0]), Some([1.0, 0.0, 1.0])).unwrap();
        assert!((f.x[0] - 1.0).abs() < 1e-15 && f.x[2].abs() < 1e-15);
        // Parallel ref_direction: undefined.
        assert!(build_axes(Some([0.0, 0.0, 1.0]), Some([0.0, 0.0, -3.0])).is_none());
    }

    #[test]
    fn angular_extent_is_the_complement_of_the_largest_gap() {
        let (a, b) = angular_extent(vec![3.0, -3.0, 3.1]).unwrap();
        // Points near pi on both sides: the extent runs over pi, not through 0.
        assert!(
            (a - 3.0).abs() < 1e-12 && (b - (TAU - 3.0)).abs() < 1e-12,
            "{a} {b}"
        );
        let (a, b) = angular_extent(vec![0.1, 1.0, 0.5]).unwrap();
        assert!((a - 0.1).abs() < 1e-12 && (b - 1.0).abs() < 1e-12);
    }

    #[test]
    fn forward_ranges() {
        assert_eq!(forward_range(1.0, 2.0, None), Some((1.0, 2.0)));
        assert_eq!(forward_range(2.0, 1.0, None), None);
        let (a, b) = forward_range(6.0, 1.0, Some(TAU)).unwrap();
        assert!((a - 6.0).abs() < 1e-15 && (b - (1.0 + TAU)).abs() < 1e-12);
        assert_eq!(forward_range(1.0, 1.0, Some(TAU)), Some((1.0, 1.0 + TAU)));
    }
}
