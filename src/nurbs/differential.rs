//! Differential geometry of NURBS curves and surfaces from their derivatives
//! ([`derivatives`](super::derivatives)): curvature, torsion, Frenet frame and osculating
//! circle of curves; fundamental forms, Gaussian, mean and principal curvatures and
//! directions of surfaces (NURBS Book ch. 3-4 derivatives; do Carmo, *Differential Geometry
//! of Curves and Surfaces*, 1.5, 3.3; seed 004 uses the osculating circle for adaptive
//! steps).
//!
//! **Degenerate points never produce NaN.** A vanishing first derivative is an error for
//! curvature, Frenet frame and osculating circle (the tangent alone has a documented limit
//! fallback, [`NurbsCurve::tangent`]); zero curvature gives torsion `None` and no osculating
//! circle; a surface point where `S_u x S_v` vanishes has no fundamental forms (error), though
//! [`NurbsSurface::normal`] still gives its limit normal.
//!
//! **Sign convention (surfaces):** the normal is `n = S_u x S_v / |S_u x S_v|`; the second
//! fundamental form is `L = S_uu . n`, `M = S_uv . n`, `N = S_vv . n`; normal curvatures
//! `k = II(d) / I(d)` are positive where the surface bends *towards* `n`. A sphere of radius
//! `r` therefore has `K = 1/r^2` and `H = +1/r` when `n` points inwards, `H = -1/r` when it
//! points outwards.

use super::knots::find_span;
use super::vector::{cross, dot, norm, scale};
use super::{GeometryError, NurbsCurve, NurbsSurface, Point3};

/// Curvature and torsion of a curve at one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveCurvature {
    /// `kappa = |C' x C''| / |C'|^3 >= 0`; exactly 0 where `C' x C''` vanishes (below
    /// `1e-10 |C'| |C''|`, i.e. `C''` parallel to `C'` up to rounding).
    pub curvature: f64,
    /// For 2-D curves: `(x' y'' - y' x'') / |C'|^3`, positive when the curve turns
    /// counter-clockwise; `None` for 3-D curves.
    pub signed_curvature: Option<f64>,
    /// `tau = det(C', C'', C''') / |C' x C''|^2`; `None` where the curvature is 0 (no
    /// osculating plane, torsion undefined).
    pub torsion: Option<f64>,
}

/// The Frenet frame of a curve at one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrenetFrame {
    /// The point `C(u)`.
    pub point: Point3,
    /// Unit tangent `T = C' / |C'|`.
    pub tangent: Point3,
    /// Unit principal normal `N = B x T` (towards the centre of curvature); `None` where
    /// the curvature is 0.
    pub normal: Option<Point3>,
    /// Unit binormal `B = C' x C'' / |C' x C''|`; `None` where the curvature is 0.
    pub binormal: Option<Point3>,
}

/// The osculating circle of a curve at one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OsculatingCircle {
    /// Centre `C + N / kappa`.
    pub center: Point3,
    /// Radius `1 / kappa`.
    pub radius: f64,
    /// Unit normal of the circle's plane: the binormal `B`.
    pub normal: Point3,
}

/// Which zero tests a curve point passed.
struct CurveLocal {
    d: [Point3; 4],
    /// `C' x C''`, zeroed when below the parallel tolerance.
    b: Point3,
    speed: f64,
}

impl NurbsCurve {
    /// `(1e-10 * size + 1e-14 * magnitude)` for the control points of the span at `u`,
    /// divided by the domain length: the speed `|C'|` below which the first derivative
    /// counts as zero (rounding far from the origin is absorbed by the second term).
    fn zero_speed(&self, u: f64) -> f64 {
        let p = self.degree();
        let span = find_span(p, self.num_poles(), self.knots(), u);
        let pts = &self.control_points()[span - p..=span];
        let (lo, hi) = super::bounding_box(pts);
        let mag = pts.iter().flatten().fold(0.0_f64, |m, c| m.max(c.abs()));
        let size = super::distance(lo, hi);
        let (a, b) = self.domain();
        (1e-10 * size + 1e-14 * mag) / (b - a)
    }

    fn local(&self, u: f64) -> Result<CurveLocal, GeometryError> {
        let ders = self.derivatives(u, 3)?;
        let d = [ders[0], ders[1], ders[2], ders[3]];
        let speed = norm(d[1]);
        if speed <= self.zero_speed(u) {
            return Err(GeometryError::InvalidArgument(format!(
                "curve has a zero first derivative at u = {u}: curvature and frame undefined"
            )));
        }
        let mut b = cross(d[1], d[2]);
        if norm(b) <= 1e-10 * speed * norm(d[2]) {
            b = [0.0; 3];
        }
        Ok(CurveLocal { d, b, speed })
    }

    /// The unit tangent at `u` (direction of `C'`). Where `C'` vanishes (a cusp or
    /// repeated control points) the tangent is the direction of the first non-vanishing
    /// derivative `C^(k)`, `k <= 8`: the limit direction of the chord `C(u + h) - C(u)` as
    /// `h -> 0+` (at the domain end, of `C(u) - C(u - h)`, which is `(-1)^(k+1) C^(k)`). Errors when every
    /// derivative up to order 8 vanishes or `u` is outside the domain.
    pub fn tangent(&self, u: f64) -> Result<Point3, GeometryError> {
        let (_, end) = self.domain();
        let ders = self.derivatives(u, 8)?;
        let tol = self.zero_speed(u);
        let len = end - self.domain().0;
        for (k, d) in ders.iter().enumerate().skip(1) {
            // Compare in domain-normalised units: C^(k) L^(k-1) has the units of C' .
            let n = norm(*d);
            if n * len.powi(k as i32 - 1) > tol {
                let sign = if u >= end && k % 2 == 0 { -1.0 } else { 1.0 };
                return Ok(scale(*d, sign / n));
            }
        }
        Err(GeometryError::InvalidArgument(format!(
            "no tangent at u = {u}: every derivative up to order 8 vanishes"
        )))
    }

    /// Curvature, signed curvature (2-D) and torsion at `u` (do Carmo 1.5). Errors where
    /// `C'` vanishes or `u` is outside the domain.
    pub fn curvature(&self, u: f64) -> Result<CurveCurvature, GeometryError> {
        let l = self.local(u)?;
        let s3 = l.speed * l.speed * l.speed;
        let bn = norm(l.b);
        let curvature = bn / s3;
        let signed_curvature = (self.dimension() == 2).then(|| {
            if bn == 0.0 {
                0.0
            } else {
                (l.d[1][0] * l.d[2][1] - l.d[1][1] * l.d[2][0]) / s3
            }
        });
        let torsion = (bn > 0.0).then(|| dot(l.b, l.d[3]) / (bn * bn));
        Ok(CurveCurvature {
            curvature,
            signed_curvature,
            torsion,
        })
    }

    /// The Frenet frame at `u`. Errors where `C'` vanishes or `u` is outside the domain;
    /// normal and binormal are `None` where the curvature is 0.
    pub fn frenet_frame(&self, u: f64) -> Result<FrenetFrame, GeometryError> {
        let l = self.local(u)?;
        let tangent = scale(l.d[1], 1.0 / l.speed);
        let bn = norm(l.b);
        let (normal, binormal) = if bn > 0.0 {
            let b = scale(l.b, 1.0 / bn);
            (Some(cross(b, tangent)), Some(b))
        } else {
            (None, None)
        };
        Ok(FrenetFrame {
            point: l.d[0],
            tangent,
            normal,
            binormal,
        })
    }

    /// The osculating circle at `u`; `Ok(None)` where the curvature is 0 (the circle
    /// degenerates to the tangent line). Errors where `C'` vanishes or `u` is outside the
    /// domain.
    pub fn osculating_circle(&self, u: f64) -> Result<Option<OsculatingCircle>, GeometryError> {
        let f = self.frenet_frame(u)?;
        let k = self.curvature(u)?.curvature;
        Ok(match (f.normal, f.binormal) {
            (Some(n), Some(b)) if k > 0.0 => {
                let radius = 1.0 / k;
                let center = [
                    f.point[0] + n[0] * radius,
                    f.point[1] + n[1] * radius,
                    f.point[2] + n[2] * radius,
                ];
                Some(OsculatingCircle {
                    center,
                    radius,
                    normal: b,
                })
            }
            _ => None,
        })
    }
}

/// First and second fundamental forms of a surface at one point (do Carmo 2.5, 3.3), with
/// the normal they refer to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FundamentalForms {
    /// `E = S_u . S_u`.
    pub e: f64,
    /// `F = S_u . S_v`.
    pub f: f64,
    /// `G = S_v . S_v`.
    pub g: f64,
    /// `L = S_uu . n`.
    pub l: f64,
    /// `M = S_uv . n`.
    pub m: f64,
    /// `N = S_vv . n`.
    pub n: f64,
    /// The unit normal `S_u x S_v / |S_u x S_v|`.
    pub normal: Point3,
    /// `S_u`.
    pub su: Point3,
    /// `S_v`.
    pub sv: Point3,
}

/// Curvatures of a surface at one point (sign convention in the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceCurvature {
    /// Gaussian curvature `K = (LN - M^2) / (EG - F^2) = k1 k2`.
    pub gaussian: f64,
    /// Mean curvature `H = (EN - 2FM + GL) / (2 (EG - F^2)) = (k1 + k2) / 2`.
    pub mean: f64,
    /// Larger principal curvature `H + sqrt(H^2 - K)`.
    pub k1: f64,
    /// Smaller principal curvature `H - sqrt(H^2 - K)`.
    pub k2: f64,
    /// Unit principal direction of `k1` (3-D, tangent to the surface).
    pub dir1: Point3,
    /// Unit principal direction of `k2`: `normal x dir1`.
    pub dir2: Point3,
    /// The unit normal the curvatures refer to.
    pub normal: Point3,
    /// Whether the point is umbilic (`k1 - k2 <= 2e-7 max(|k1|, |k2|)`, or below
    /// `2e-12 / size` with `size` the local control-net size): then every direction is
    /// principal and `dir1` is `S_u` normalised.
    pub umbilic: bool,
}

impl NurbsSurface {
    /// First and second fundamental forms at `(u, v)`. Errors where `S_u x S_v` vanishes
    /// (a sphere pole, a collapsed edge: the parametrisation is singular there, even if
    /// [`normal`](Self::normal) has a limit) or outside the domain.
    pub fn fundamental_forms(&self, u: f64, v: f64) -> Result<FundamentalForms, GeometryError> {
        let skl = self.derivatives(u, v, 2)?;
        let (su, sv) = (skl[1][0], skl[0][1]);
        let (suu, suv, svv) = (skl[2][0], skl[1][1], skl[0][2]);
        let c = cross(su, sv);
        let ((u0, u1), (v0, v1)) = self.domain();
        let (tol, size) = self.local_size_tolerance(u, v);
        if norm(c) * (u1 - u0) * (v1 - v0) <= tol * size.max(tol) {
            return Err(GeometryError::InvalidArgument(format!(
                "singular parametrisation at (u, v) = ({u}, {v}): S_u x S_v vanishes"
            )));
        }
        let normal = scale(c, 1.0 / norm(c));
        Ok(FundamentalForms {
            e: dot(su, su),
            f: dot(su, sv),
            g: dot(sv, sv),
            l: dot(suu, normal),
            m: dot(suv, normal),
            n: dot(svv, normal),
            normal,
            su,
            sv,
        })
    }

    /// Gaussian, mean and principal curvatures and principal directions at `(u, v)`
    /// (do Carmo 3.3). Errors where the parametrisation is singular (see
    /// [`fundamental_forms`](Self::fundamental_forms)) or outside the domain.
    pub fn curvature(&self, u: f64, v: f64) -> Result<SurfaceCurvature, GeometryError> {
        let ff = self.fundamental_forms(u, v)?;
        let (e, f, g, l, m, n) = (ff.e, ff.f, ff.g, ff.l, ff.m, ff.n);
        let det = e * g - f * f;
        let gaussian = (l * n - m * m) / det;
        let mean = (e * n - 2.0 * f * m + g * l) / (2.0 * det);
        // Half the distance between the principal curvatures, from the discriminant of
        // `det k^2 - (eN - 2fM + gL) k + (LN - M^2) = 0` written as a sum of squares
        // (dividing by the larger of e and g): `mean^2 - gaussian` subtracts two nearly
        // equal numbers near an umbilic and could come out negative by more than rounding,
        // which made `k1 k2` differ from the gaussian curvature.
        let (p, q, a) = if g >= e {
            (e * n - g * l, f * n - g * m, g)
        } else {
            (g * l - e * n, f * l - e * m, e)
        };
        let disc = ((p - 2.0 * f * q / a).powi(2) + 4.0 * det.max(0.0) * (q / a).powi(2)).sqrt()
            / (2.0 * det.abs());
        // The root of larger magnitude is `mean +- disc` with the sign of `mean` (no
        // cancellation); the other is `gaussian / big` by Vieta's product of the roots, since
        // `mean -+ disc` loses all digits of a curvature far smaller than the other (a nearly
        // cylindrical point: 1e-8 relative error in k1 k2 at k1 / k2 = 1e-8).
        let big = if mean >= 0.0 {
            mean + disc
        } else {
            mean - disc
        };
        let small = if big != 0.0 { gaussian / big } else { 0.0 };
        let (k1, k2) = if big >= small {
            (big, small)
        } else {
            (small, big)
        };
        // Umbilic test: relative to the curvatures themselves, with a floor of 1e-12 / size
        // for planes where both vanish up to rounding.
        let kmax = k1.abs().max(k2.abs());
        let (_, size) = self.local_size_tolerance(u, v);
        let umbilic = disc <= 1e-7 * kmax || disc * size <= 1e-12;
        let su_len = norm(ff.su);
        let dir1 = if umbilic {
            scale(ff.su, 1.0 / su_len)
        } else {
            // (L - k E) du + (M - k F) dv = 0 and (M - k F) du + (N - k G) dv = 0: take the
            // better-conditioned row (a, b), whose null direction is (du, dv) = (b, -a).
            let r1 = (l - k1 * e, m - k1 * f);
            let r2 = (m - k1 * f, n - k1 * g);
            let (a, b) = if r1.0.hypot(r1.1) >= r2.0.hypot(r2.1) {
                r1
            } else {
                r2
            };
            let d = [
                b * ff.su[0] - a * ff.sv[0],
                b * ff.su[1] - a * ff.sv[1],
                b * ff.su[2] - a * ff.sv[2],
            ];
            let dn = norm(d);
            if dn > 0.0 {
                scale(d, 1.0 / dn)
            } else {
                scale(ff.su, 1.0 / su_len)
            }
        };
        let dir2 = cross(ff.normal, dir1);
        Ok(SurfaceCurvature {
            gaussian,
            mean,
            k1,
            k2,
            dir1,
            dir2,
            normal: ff.normal,
            umbilic,
        })
    }
}
