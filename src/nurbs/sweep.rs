//! Exact NURBS surfaces swept from curves: revolution (NURBS Book A8.1), linear extrusion
//! (general cylinder, NURBS Book 8.3), ruled surfaces (NURBS Book 8.4), and the quadrics of
//! ISO 10303-42 4.4 (plane, cylinder, cone, sphere, torus) in the standard's own
//! parameterisation.
//!
//! Parameter contract: the rotation direction is always `u`, built from the arcs of
//! [`super::conic`] (the NURBS parameter equals the angle at every knot; [`ArcMap`] maps
//! angle <-> u exactly in between); straight directions (extrusion, cylinder and cone axis,
//! plane) keep the standard's parameter unchanged (identity map); a profile keeps its own
//! parameter.

use super::conic::{ArcMap, ConicKind, arc_knots, arc_poles, conic_arc, line_segment};
use super::vector::{add, cross, dot, scale, sub};
use super::{GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};

/// A right-handed orthonormal placement (ISO 10303-42 axis2_placement_3d after its axes are
/// built): location and the unit vectors x (ref_direction), y = z x x, z (axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Location.
    pub origin: Point3,
    /// First axis.
    pub x: Point3,
    /// Second axis.
    pub y: Point3,
    /// Third axis (the axis of revolution of the quadrics).
    pub z: Point3,
}

fn check_frame(f: &Frame) -> Result<(), GeometryError> {
    let axes = [f.x, f.y, f.z];
    let ok = [f.origin, f.x, f.y, f.z]
        .iter()
        .flatten()
        .all(|c| c.is_finite())
        && axes.iter().all(|a| (dot(*a, *a) - 1.0).abs() <= 1e-9)
        && dot(f.x, f.y).abs() <= 1e-9
        && dot(f.y, f.z).abs() <= 1e-9
        && dot(f.z, f.x).abs() <= 1e-9;
    if ok {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(
            "placement axes are not finite orthonormal unit vectors".into(),
        ))
    }
}

fn check_range(name: &str, r: (f64, f64)) -> Result<(), GeometryError> {
    if r.0.is_finite() && r.1.is_finite() && r.0 < r.1 {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(format!(
            "{name} range [{}, {}] is not an increasing finite interval",
            r.0, r.1
        )))
    }
}

/// One row of a rotation net: the circle of pole `j` is `centre + cos t d + sin t e`, and
/// the pole's own weight multiplies the arc's weights.
struct Row {
    centre: Point3,
    d: Point3,
    e: Point3,
    weight: f64,
}

/// The tensor-product net of the rotation arcs (u) of every profile pole (v): A8.1. The
/// surface is the profile rotated, because rotation is linear and the arc weights do not
/// depend on the pole.
fn rotation_net(
    map: &ArcMap,
    rows: &[Row],
    profile: &NurbsCurve,
) -> Result<NurbsSurface, GeometryError> {
    let unit = arc_poles(map, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let (arc, arc_w) = (&unit.0, &unit.1);
    let (nu, nv) = (arc.len(), rows.len());
    let points = Grid::from_fn(nu, nv, |i, j| {
        let r = &rows[j];
        add(r.centre, add(scale(r.d, arc[i][0]), scale(r.e, arc[i][1])))
    });
    let weights = Grid::from_fn(nu, nv, |i, j| arc_w[i] * rows[j].weight);
    NurbsSurface::new(
        2,
        profile.degree(),
        arc_knots(map),
        profile.knots().to_vec(),
        points,
        Some(weights),
    )
}

/// The profile rotated about the axis through `axis_point` with unit direction `axis` by
/// `theta` in `[theta0, theta1]` (right-hand rule about `axis`): u = rotation (conic arcs,
/// mapped by the returned [`ArcMap`]), v = the profile's parameter. NURBS Book A8.1.
pub fn revolve(
    profile: &NurbsCurve,
    axis_point: Point3,
    axis: Point3,
    theta0: f64,
    theta1: f64,
) -> Result<(NurbsSurface, ArcMap), GeometryError> {
    if !axis_point.iter().chain(axis.iter()).all(|c| c.is_finite())
        || (dot(axis, axis) - 1.0).abs() > 1e-9
    {
        return Err(GeometryError::InvalidArgument(
            "axis of revolution is not a finite unit vector".into(),
        ));
    }
    // The arc layout of the sweep (checked); `rotation_net` builds the unit circle's arc.
    let map = ArcMap::new(ConicKind::Elliptic, theta0, theta1)?;
    let rows: Vec<Row> = profile
        .control_points()
        .iter()
        .enumerate()
        .map(|(j, &p)| {
            let centre = add(axis_point, scale(axis, dot(sub(p, axis_point), axis)));
            let d = sub(p, centre);
            Row {
                centre,
                d,
                e: cross(axis, d),
                weight: profile.weight(j),
            }
        })
        .collect();
    Ok((rotation_net(&map, &rows, profile)?, map))
}

/// `S(u, v) = C(u) + v d` for `v` in `[v0, v1]` (`d` keeps its length): u = the curve's
/// parameter, v unchanged. NURBS Book 8.3 (general cylinder).
pub fn extrude(
    curve: &NurbsCurve,
    d: Point3,
    v0: f64,
    v1: f64,
) -> Result<NurbsSurface, GeometryError> {
    check_range("extrusion", (v0, v1))?;
    if !d.iter().all(|c| c.is_finite()) {
        return Err(GeometryError::InvalidArgument(
            "extrusion vector is not finite".into(),
        ));
    }
    let poles = curve.control_points();
    let points = Grid::from_fn(poles.len(), 2, |i, j| {
        add(poles[i], scale(d, if j == 0 { v0 } else { v1 }))
    });
    let weights = curve
        .weights()
        .map(|w| Grid::from_fn(w.len(), 2, |i, _| w[i]));
    NurbsSurface::new(
        curve.degree(),
        1,
        curve.knots().to_vec(),
        vec![v0, v0, v1, v1],
        points,
        weights,
    )
}

/// The knots of `b` missing from `a` (as a multiset), for refinement to a common vector.
fn missing_knots(a: &[f64], b: &[f64]) -> Vec<f64> {
    let (mut i, mut out) = (0, Vec::new());
    for &k in b {
        while i < a.len() && a[i] < k {
            i += 1;
        }
        if i < a.len() && a[i] == k {
            i += 1;
        } else {
            out.push(k);
        }
    }
    out
}

/// Product of two Bernstein polynomials of degrees p and q (coefficients `a`, `b`), as the
/// degree p + q coefficients: `c_k = sum_{i+j=k} C(p,i) C(q,j) / C(p+q,k) a_i b_j`.
fn bernstein_product(a: &[[f64; 4]], b: &[f64]) -> Vec<[f64; 4]> {
    let (p, q) = (a.len() - 1, b.len() - 1);
    let binom = |n: usize, k: usize| -> f64 {
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    };
    (0..=p + q)
        .map(|k| {
            let mut c = [0.0; 4];
            for i in k.saturating_sub(q)..=k.min(p) {
                let f = binom(p, i) * binom(q, k - i) / binom(p + q, k) * b[k - i];
                for (cc, ai) in c.iter_mut().zip(a[i]) {
                    *cc += f * ai;
                }
            }
            c
        })
        .collect()
}

/// The ruled surface `S(u, v) = (1 - v) C0(u) + v C1(u)`, `v` in `[0, 1]`, u on C0's
/// domain (C1 is reparameterised affinely onto it). NURBS Book 8.4: the curves are made
/// compatible (degree elevation A5.9, knot refinement A5.4) and become the two rows of a
/// degree-1 net. When both are rational with different weight functions the rows do not
/// share a denominator; then each row is multiplied by the other curve's weight function
/// (numerator and denominator alike, segment by segment in Bernstein form), which gives both
/// rows the denominator W0 W1 at degree p0 + p1: still exact.
pub fn ruled(c0: &NurbsCurve, c1: &NurbsCurve) -> Result<NurbsSurface, GeometryError> {
    let (a, b) = c0.domain();
    let c1 = c1.reparameterize(a, b)?;
    let p = c0.degree().max(c1.degree());
    let raise = |c: &NurbsCurve| match p - c.degree() {
        0 => Ok(c.clone()),
        t => c.elevate(t),
    };
    let mut c0 = raise(c0)?;
    let mut c1 = raise(&c1)?;
    let add0 = missing_knots(c0.knots(), c1.knots());
    let add1 = missing_knots(c1.knots(), c0.knots());
    if !add0.is_empty() {
        c0 = c0.refine(&add0)?;
    }
    if !add1.is_empty() {
        c1 = c1.refine(&add1)?;
    }
    let same_weights = match (c0.weights(), c1.weights()) {
        (None, None) => true,
        (Some(w0), Some(w1)) => w0 == w1,
        _ => false,
    };
    if same_weights {
        let (r0, r1) = (c0.control_points(), c1.control_points());
        let points = Grid::from_fn(r0.len(), 2, |i, j| if j == 0 { r0[i] } else { r1[i] });
        let weights = c0.weights().map(|w| Grid::from_fn(w.len(), 2, |i, _| w[i]));
        return NurbsSurface::new(
            p,
            1,
            c0.knots().to_vec(),
            vec![0.0, 0.0, 1.0, 1.0],
            points,
            weights,
        );
    }
    // Rows (N0 W1, W0 W1) and (N1 W0, W1 W0), per Bezier segment.
    let (s0, s1) = (c0.bezier_segments()?, c1.bezier_segments()?);
    if s0.len() != s1.len() {
        return Err(GeometryError::InvalidArgument(
            "ruled surface: the curves did not decompose into matching segments".into(),
        ));
    }
    let degree = 2 * p;
    let mut rows: [Vec<[f64; 4]>; 2] = [Vec::new(), Vec::new()];
    let mut knots = vec![a; degree + 1];
    for (k, (g0, g1)) in s0.iter().zip(&s1).enumerate() {
        let (h0, h1) = (g0.homogeneous(), g1.homogeneous());
        let w0: Vec<f64> = h0.iter().map(|h| h[3]).collect();
        let w1: Vec<f64> = h1.iter().map(|h| h[3]).collect();
        for (row, seg) in rows
            .iter_mut()
            .zip([bernstein_product(&h0, &w1), bernstein_product(&h1, &w0)])
        {
            // Consecutive segments share their end pole (the curve is continuous).
            let skip = usize::from(k > 0);
            row.extend_from_slice(&seg[skip..]);
        }
        let end = g0.domain().1;
        if k + 1 < s0.len() {
            knots.extend(std::iter::repeat_n(end, degree));
        }
    }
    knots.extend(std::iter::repeat_n(b, degree + 1));
    let n = rows[0].len();
    let net = Grid::from_fn(n, 2, |i, j| rows[j][i]);
    NurbsSurface::from_homogeneous(degree, 1, knots, vec![0.0, 0.0, 1.0, 1.0], &net, true, 3)
}

/// The plane `O + u x + v y` on `u x v` (ISO 10303-42 4.4.2): a bilinear patch, identity
/// maps.
pub fn plane(f: &Frame, u: (f64, f64), v: (f64, f64)) -> Result<NurbsSurface, GeometryError> {
    check_frame(f)?;
    check_range("u", u)?;
    check_range("v", v)?;
    let edge = line_segment(
        add(f.origin, scale(f.x, u.0)),
        add(f.origin, scale(f.x, u.1)),
        u.0,
        u.1,
    )?;
    extrude(&edge, f.y, v.0, v.1)
}

/// A profile given in the frame's (radius along x, height along z) half-plane, rotated
/// about z by `u` (x towards y): the quadrics' common construction.
fn revolve_in_frame(
    f: &Frame,
    profile: &NurbsCurve,
    u: (f64, f64),
) -> Result<(NurbsSurface, ArcMap), GeometryError> {
    check_frame(f)?;
    let map = ArcMap::new(ConicKind::Elliptic, u.0, u.1)?;
    let rows: Vec<Row> = profile
        .control_points()
        .iter()
        .enumerate()
        .map(|(j, &[rho, h, _])| Row {
            centre: add(f.origin, scale(f.z, h)),
            d: scale(f.x, rho),
            e: scale(f.y, rho),
            weight: profile.weight(j),
        })
        .collect();
    Ok((rotation_net(&map, &rows, profile)?, map))
}

/// The exact inverse of a quadric's parameterisation ([`cylinder`], [`cone`], [`sphere`],
/// [`torus`]): the NURBS parameters of a point of the surface in closed form, and the
/// [`ArcMap`]s of its angular directions. The angle about the axis is `atan2` of the point's
/// frame coordinates (ISO 10303-42 4.4.3-4.4.6 measure it from x towards y), the height
/// along a cylinder's or cone's axis is the point's z coordinate (identity map), and the
/// angle round a torus's tube (or a sphere's latitude) is `atan2` of the height over the
/// distance from the tube's centre circle; angles go to NURBS parameters through the exact
/// [`ArcMap::to_nurbs`]. For a point off the surface these are the parameters of its radial
/// projection; callers compare the surface point there with the point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadricMap {
    frame: Frame,
    u: ArcMap,
    axial: Axial,
}

/// The direction along the axis of a [`QuadricMap`].
#[derive(Debug, Clone, Copy, PartialEq)]
enum Axial {
    /// Cylinder and cone: `v` is the height, in `range`; the radius there is `r + v tan`.
    Height { r: f64, tan: f64, range: (f64, f64) },
    /// Sphere (`major = 0`) and torus: `v` is the tube angle, mapped.
    Tube { major: f64, map: ArcMap },
}

impl QuadricMap {
    /// The map of the rotation direction `u` (angle <-> NURBS parameter).
    pub fn u(&self) -> &ArcMap {
        &self.u
    }

    /// The map of `v` when it is an angle (sphere, torus); `None` for the identity of a
    /// cylinder's or cone's height.
    pub fn v(&self) -> Option<&ArcMap> {
        match &self.axial {
            Axial::Height { .. } => None,
            Axial::Tube { map, .. } => Some(map),
        }
    }

    /// The NURBS parameters `(u, v)` of point `p` (see the type), inside the surface's
    /// domain. An angle outside its direction's range is taken a whole turn round when that
    /// lands inside, else to the nearer end (around the circle); at the seam of a whole turn
    /// either end may come out. A height outside the range is clamped into it.
    pub fn parameters(&self, p: Point3) -> (f64, f64) {
        let f = &self.frame;
        let q = sub(p, f.origin);
        let (x, y, z) = (dot(q, f.x), dot(q, f.y), dot(q, f.z));
        let (angle, v) = match self.axial {
            Axial::Height { r, tan, range } => {
                // Past a cone's apex the radius is negative: the point lies opposite.
                let flip = r + z * tan < 0.0;
                let angle = if flip { (-y).atan2(-x) } else { y.atan2(x) };
                (angle, z.clamp(range.0, range.1))
            }
            Axial::Tube { major, map } => {
                let tube = z.atan2(x.hypot(y) - major);
                (y.atan2(x), map.to_nurbs(into_range(tube, map.range())))
            }
        };
        (self.u.to_nurbs(into_range(angle, self.u.range())), v)
    }
}

/// Angle `a` moved by whole turns into `[lo, hi]` when it fits, else the end of the range
/// nearer round the circle.
fn into_range(a: f64, (lo, hi): (f64, f64)) -> f64 {
    let tau = std::f64::consts::TAU;
    let x = lo + (a - lo).rem_euclid(tau);
    if x <= hi {
        x
    } else if x - hi <= lo + tau - x {
        hi
    } else {
        lo
    }
}

/// The cylinder `O + r (cos u x + sin u y) + v z` (ISO 10303-42 4.4.3): u angle (mapped),
/// v identity.
pub fn cylinder(
    f: &Frame,
    r: f64,
    u: (f64, f64),
    v: (f64, f64),
) -> Result<(NurbsSurface, QuadricMap), GeometryError> {
    cone(f, r, 0.0, u, v)
}

/// The cone `O + (r + v tan a)(cos u x + sin u y) + v z` (ISO 10303-42 4.4.4, `a` the
/// semi-angle, `v` along the axis): u angle (mapped), v identity.
pub fn cone(
    f: &Frame,
    r: f64,
    semi_angle: f64,
    u: (f64, f64),
    v: (f64, f64),
) -> Result<(NurbsSurface, QuadricMap), GeometryError> {
    check_range("v", v)?;
    if !(r.is_finite() && semi_angle.is_finite() && semi_angle.abs() < std::f64::consts::FRAC_PI_2)
    {
        return Err(GeometryError::InvalidArgument(format!(
            "cone radius {r} / semi-angle {semi_angle} out of range"
        )));
    }
    let t = semi_angle.tan();
    let profile = line_segment([r + v.0 * t, v.0, 0.0], [r + v.1 * t, v.1, 0.0], v.0, v.1)?;
    let (surface, map) = revolve_in_frame(f, &profile, u)?;
    Ok((
        surface,
        QuadricMap {
            frame: *f,
            u: map,
            axial: Axial::Height {
                r,
                tan: t,
                range: v,
            },
        },
    ))
}

/// The sphere `O + r cos v (cos u x + sin u y) + r sin v z` (ISO 10303-42 4.4.5), v in
/// `[-pi/2, pi/2]`: u and v both angles (mapped).
pub fn sphere(
    f: &Frame,
    r: f64,
    u: (f64, f64),
    v: (f64, f64),
) -> Result<(NurbsSurface, QuadricMap), GeometryError> {
    let lim = std::f64::consts::FRAC_PI_2 * (1.0 + 1e-12);
    if v.0 < -lim || v.1 > lim {
        return Err(GeometryError::InvalidArgument(format!(
            "sphere latitude range [{}, {}] leaves [-pi/2, pi/2]",
            v.0, v.1
        )));
    }
    torus(f, 0.0, r, u, v)
}

/// The torus `O + (R + r cos v)(cos u x + sin u y) + r sin v z` (ISO 10303-42 4.4.6):
/// u and v both angles (mapped). `R = 0` is the sphere.
pub fn torus(
    f: &Frame,
    major: f64,
    minor: f64,
    u: (f64, f64),
    v: (f64, f64),
) -> Result<(NurbsSurface, QuadricMap), GeometryError> {
    if !(major.is_finite() && minor.is_finite()) {
        return Err(GeometryError::InvalidArgument(
            "torus radii are not finite".into(),
        ));
    }
    let (profile, vmap) = conic_arc(
        ConicKind::Elliptic,
        [major, 0.0, 0.0],
        [minor, 0.0, 0.0],
        [0.0, minor, 0.0],
        v.0,
        v.1,
    )?;
    let (surface, umap) = revolve_in_frame(f, &profile, u)?;
    Ok((
        surface,
        QuadricMap {
            frame: *f,
            u: umap,
            axial: Axial::Tube { major, map: vmap },
        },
    ))
}
