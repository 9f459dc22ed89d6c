//! Exact constructions (conic arcs A7.1, sweeps A8.1, ruled surfaces, ISO 10303-42 quadrics)
//! checked against the analytic definitions they claim to represent, evaluated directly
//! (trigonometric / hyperbolic formulas, Rodrigues' rotation formula), never against the
//! constructions' own output.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{Ends, arb_curve, cross, dist, dot, norm, sub};
use nurbsx::nurbs::conic::{ConicKind, conic_arc, line_segment, parabola_arc, polyline};
use nurbsx::nurbs::sweep::{self, Frame};
use nurbsx::nurbs::{NurbsCurve, Point3};
use proptest::prelude::*;

type F64Fn = fn(f64) -> f64;

fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: Point3, s: f64) -> Point3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn unit(a: Point3) -> Point3 {
    scale(a, 1.0 / norm(a))
}

/// An orthonormal right-handed frame from two random vectors (Gram-Schmidt).
fn frame(origin: Point3, a: Point3, b: Point3) -> Option<Frame> {
    let z = unit(a);
    let x = sub(b, scale(z, dot(b, z)));
    if norm(a) < 0.1 || norm(x) < 0.1 {
        return None;
    }
    let x = unit(x);
    Some(Frame {
        origin,
        x,
        y: cross(z, x),
        z,
    })
}

fn arb_vec(r: f64) -> impl Strategy<Value = Point3> {
    prop::array::uniform3(-r..r)
}

fn arb_frame() -> impl Strategy<Value = Frame> {
    (arb_vec(50.0), arb_vec(1.0), arb_vec(1.0)).prop_filter_map("frame", |(o, a, b)| frame(o, a, b))
}

/// Rotation of `p` about the axis through `c` with unit direction `k` by `t` (Rodrigues).
fn rotate(p: Point3, c: Point3, k: Point3, t: f64) -> Point3 {
    let v = sub(p, c);
    let r = add(
        add(scale(v, t.cos()), scale(cross(k, v), t.sin())),
        scale(k, dot(k, v) * (1.0 - t.cos())),
    );
    add(c, r)
}

/// The k-th of n equal steps from a to b, landing on b exactly at k = n.
fn step(a: f64, b: f64, k: usize, n: usize) -> f64 {
    if k == n {
        b
    } else {
        a + (b - a) * (k as f64 / n as f64)
    }
}

fn close(a: Point3, b: Point3, tol: f64) -> bool {
    dist(a, b) <= tol
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Points and first derivatives of elliptic and hyperbolic arcs equal the conic's own
    /// formulas at the mapped parameters; the map is inverted exactly; knots are the segment
    /// ends' parameters.
    #[test]
    fn conic_arcs_follow_their_definition(
        c in arb_vec(100.0), x in arb_vec(10.0), y in arb_vec(10.0),
        hyperbolic in any::<bool>(), start in -7.0f64..7.0, sweep in 0.01f64..1.0,
    ) {
        let kind = if hyperbolic { ConicKind::Hyperbolic } else { ConicKind::Elliptic };
        let sweep = if hyperbolic { sweep * 6.0 } else { sweep * std::f64::consts::TAU };
        let (t0, t1) = (start, start + sweep);
        let (curve, map) = conic_arc(kind, c, x, y, t0, t1).unwrap();
        prop_assert_eq!(curve.domain(), (t0, t1));
        let [f, g, df, dg]: [F64Fn; 4] =
            if hyperbolic { [f64::cosh, f64::sinh, f64::sinh, f64::cosh] } else {
                [f64::cos, f64::sin, |t| -t.sin(), f64::cos]
            };
        let reach = if hyperbolic { t0.abs().max(t1.abs()).cosh() } else { 1.0 };
        let size = norm(c) + (norm(x) + norm(y)) * reach;
        for k in 0..=40 {
            let t = step(t0, t1, k, 40);
            let u = map.to_nurbs(t);
            prop_assert!((map.from_nurbs(u) - t).abs() <= 1e-12 * (1.0 + t.abs()), "inverse at {}", t);
            let want = add(c, add(scale(x, f(t)), scale(y, g(t))));
            let d = curve.derivatives(u, 1).unwrap();
            prop_assert!(close(d[0], want, 1e-13 * size), "point at t={t}: {:?} vs {:?}", d[0], want);
            let want_d = add(scale(x, df(t)), scale(y, dg(t)));
            let got_d = scale(d[1], map.derivative(t));
            prop_assert!(close(got_d, want_d, 1e-10 * size), "derivative at t={t}: {:?} vs {:?}", got_d, want_d);
        }
        // Interior knots of multiplicity 2 at the equal segment ends, which the map fixes.
        let n = map.segments();
        prop_assert_eq!(curve.knots().len(), 2 * n + 4);
        for i in 1..n {
            let k = t0 + (t1 - t0) * i as f64 / n as f64;
            prop_assert!((curve.knots()[1 + 2 * i] - k).abs() <= 1e-15 * (1.0 + k.abs()));
            prop_assert_eq!(map.to_nurbs(curve.knots()[1 + 2 * i]), curve.knots()[1 + 2 * i]);
        }
    }

    /// The second derivative by the chain rule (d2C/dt2 = C'' (du/dt)^2 + C' d2u/dt2, with
    /// d2u/dt2 by a central difference of the map's own derivative) matches -cos t X - sin t Y.
    #[test]
    fn circle_second_derivative(r in 0.1f64..100.0, start in -4.0f64..4.0, sweep in 0.1f64..std::f64::consts::TAU) {
        let (curve, map) = conic_arc(ConicKind::Elliptic, [0.0; 3], [r, 0.0, 0.0], [0.0, r, 0.0], start, start + sweep).unwrap();
        for k in 0..20 {
            // Off the knots, where C'' and the map's derivative jump.
            let t = start + sweep * (k as f64 + 0.37) / 20.0;
            let u = map.to_nurbs(t);
            let d = curve.derivatives(u, 2).unwrap();
            let h = 1e-5;
            let d2u = (map.derivative(t + h) - map.derivative(t - h)) / (2.0 * h);
            let du = map.derivative(t);
            let got = add(scale(d[2], du * du), scale(d[1], d2u));
            let want = [-r * t.cos(), -r * t.sin(), 0.0];
            // The difference quotient limits this check to ~1e-6 relative.
            prop_assert!(close(got, want, 1e-6 * r), "t={t}: {:?} vs {:?}", got, want);
            // The radius is exact everywhere, not only at samples of the map.
            prop_assert!((norm(d[0]) - r).abs() <= 1e-13 * r);
        }
    }

    /// A random (rational) profile rotated about a random axis equals the profile's points
    /// rotated by Rodrigues' formula at the mapped angle.
    #[test]
    fn revolution_is_the_rotated_profile(
        profile in arb_curve(3, true, Ends::Clamped), c in arb_vec(10.0), k in arb_vec(1.0),
        start in -3.0f64..3.0, sweep in 0.1f64..std::f64::consts::TAU,
    ) {
        prop_assume!(norm(k) > 0.1);
        let k = unit(k);
        let (s, map) = sweep::revolve(&profile, c, k, start, start + sweep).unwrap();
        let (a, b) = profile.domain();
        for i in 0..=8 {
            let t = step(start, start + sweep, i, 8);
            for j in 0..=8 {
                let v = step(a, b, j, 8);
                let want = rotate(profile.point_at(v).unwrap(), c, k, t);
                let got = s.point_at(map.to_nurbs(t), v).unwrap();
                prop_assert!(close(got, want, 1e-11 * 100.0), "({t}, {v}): {:?} vs {:?}", got, want);
            }
        }
    }

    /// Cylinder, cone, sphere and torus equal the ISO 10303-42 4.4 formulas at the mapped
    /// parameters, and the plane is O + u x + v y. The closed-form inverse of each quadric's
    /// parameterisation (`QuadricMap::parameters`) takes the formula's point back to those
    /// mapped parameters, also past a cone's apex.
    #[test]
    fn quadrics_follow_iso_10303_42(
        f in arb_frame(), r in 0.5f64..20.0, minor in 0.1f64..0.5, a in -1.2f64..1.2,
        u0 in -3.0f64..3.0, du in 0.1f64..std::f64::consts::TAU, v0 in -20.0f64..20.0, dv in 0.1f64..30.0,
    ) {
        let (u1, v1) = (u0 + du, v0 + dv);
        let at = |rho: f64, h: f64, u: f64| add(f.origin, add(scale(add(scale(f.x, u.cos()), scale(f.y, u.sin())), rho), scale(f.z, h)));
        let tol = 1e-11 * (norm(f.origin) + r + v0.abs() + dv);
        let (cyl, cm) = sweep::cylinder(&f, r, (u0, u1), (v0, v1)).unwrap();
        let (con, km) = sweep::cone(&f, r, a, (u0, u1), (v0, v1)).unwrap();
        let pl = sweep::plane(&f, (u0, u1), (v0, v1)).unwrap();
        let (lat0, lat1) = (-1.5 + 0.3 * (u0 + 3.0) / 6.0, 1.5 * (0.2 + 0.8 * du / std::f64::consts::TAU));
        let (sph, sm) = sweep::sphere(&f, r, (u0, u1), (lat0.min(lat1 - 0.05), lat1)).unwrap();
        let (tor, tm) = sweep::torus(&f, r, r * minor, (u0, u1), (v0 * 0.1, v0 * 0.1 + du)).unwrap();
        for i in 0..=6 {
            let u = step(u0, u1, i, 6);
            for j in 0..=6 {
                let v = step(v0, v1, j, 6);
                prop_assert!(close(cyl.point_at(cm.u().to_nurbs(u), v).unwrap(), at(r, v, u), tol));
                prop_assert!(close(con.point_at(km.u().to_nurbs(u), v).unwrap(), at(r + v * a.tan(), v, u), tol * (1.0 + a.tan().abs())));
                // Inverses; a cone's radius r + v tan a is negative past its apex.
                for (m, rho) in [(&cm, r), (&km, r + v * a.tan())] {
                    let (pu, pv) = m.parameters(at(rho, v, u));
                    prop_assert!((pu - m.u().to_nurbs(u)).abs() <= 1e-9, "u {pu} at {u}");
                    prop_assert!((pv - v).abs() <= tol, "v {pv} at {v}");
                }
                let want_plane = add(f.origin, add(scale(f.x, u), scale(f.y, v)));
                prop_assert!(close(pl.point_at(u, v).unwrap(), want_plane, tol));
                let (su, sv) = (sm.u(), sm.v().unwrap());
                let (l0, l1) = su_range(sv);
                let lat = step(l0, l1, j, 6);
                prop_assert!(close(sph.point_at(su.to_nurbs(u), sv.to_nurbs(lat)).unwrap(), at(r * lat.cos(), r * lat.sin(), u), tol));
                let (pu, pv) = sm.parameters(at(r * lat.cos(), r * lat.sin(), u));
                prop_assert!((pu - su.to_nurbs(u)).abs() <= 1e-9 && (pv - sv.to_nurbs(lat)).abs() <= 1e-9, "sphere ({pu}, {pv}) at ({u}, {lat})");
                let (tu, tv) = (tm.u(), tm.v().unwrap());
                let (m0, m1) = su_range(tv);
                let w = step(m0, m1, j, 6);
                let rr = r * minor;
                prop_assert!(close(tor.point_at(tu.to_nurbs(u), tv.to_nurbs(w)).unwrap(), at(r + rr * w.cos(), rr * w.sin(), u), tol));
                let (pu, pv) = tm.parameters(at(r + rr * w.cos(), rr * w.sin(), u));
                prop_assert!((pu - tu.to_nurbs(u)).abs() <= 1e-9 && (pv - tv.to_nurbs(w)).abs() <= 1e-9, "torus ({pu}, {pv}) at ({u}, {w})");
            }
        }
    }

    /// Extrusion is C(u) + v d; a ruled surface is (1 - v) C0(u) + v C1(phi(u)) with phi the
    /// affine map of C0's domain onto C1's, for polynomial and rational curves alike.
    #[test]
    fn extrusion_and_ruled_surfaces(
        c0 in arb_curve(3, true, Ends::Clamped), c1 in arb_curve(3, true, Ends::Clamped),
        p1 in arb_curve(2, false, Ends::Clamped), d in arb_vec(5.0), v0 in -3.0f64..0.0,
    ) {
        let e = sweep::extrude(&c0, d, v0, v0 + 2.0).unwrap();
        let (a, b) = c0.domain();
        let (a1, b1) = c1.domain();
        let ruled_rational = sweep::ruled(&c0, &c1).unwrap();
        let ruled_mixed = sweep::ruled(&c0, &p1).unwrap();
        let (pa, pb) = p1.domain();
        for i in 0..=10 {
            let u = step(a, b, i, 10);
            let phi = |lo: f64, hi: f64| step(lo, hi, i, 10);
            for j in 0..=4 {
                let s = j as f64 / 4.0;
                let v = step(v0, v0 + 2.0, j, 4);
                let want = add(c0.point_at(u).unwrap(), scale(d, v));
                prop_assert!(close(e.point_at(u, v).unwrap(), want, 1e-11 * 100.0));
                let lerp = |q: &NurbsCurve, t: f64| add(scale(c0.point_at(u).unwrap(), 1.0 - s), scale(q.point_at(t).unwrap(), s));
                let got = ruled_rational.point_at(u, s).unwrap();
                prop_assert!(close(got, lerp(&c1, phi(a1, b1)), 1e-10 * 100.0), "rational ruled at ({u}, {s})");
                let got = ruled_mixed.point_at(u, s).unwrap();
                prop_assert!(close(got, lerp(&p1, phi(pa, pb)), 1e-10 * 100.0), "mixed ruled at ({u}, {s})");
            }
        }
    }
}

fn su_range(m: &nurbsx::nurbs::conic::ArcMap) -> (f64, f64) {
    m.range()
}

/// The parabola V + t^2 X + 2 t Y is the curve at parameter t, with its derivatives.
#[test]
fn parabola_is_polynomial_in_its_parameter() {
    let (v, x, y) = ([1.0, -2.0, 3.0], [0.5, 0.25, 0.0], [0.0, 0.75, -1.0]);
    let c = parabola_arc(v, x, y, -3.5, 2.25).unwrap();
    assert!(!c.is_rational());
    for k in 0..=50 {
        let t = -3.5 + 5.75 * (k as f64 / 50.0);
        let d = c.derivatives(t, 2).unwrap();
        let p = add(v, add(scale(x, t * t), scale(y, 2.0 * t)));
        assert!(dist(d[0], p) <= 1e-13 * 20.0, "{t}");
        assert!(dist(d[1], add(scale(x, 2.0 * t), scale(y, 2.0))) <= 1e-12 * 20.0);
        assert!(dist(d[2], scale(x, 2.0)) <= 1e-12 * 20.0);
    }
}

/// Lines and polylines reach each point at its parameter; bad inputs are refused.
#[test]
fn lines_and_polylines() {
    let l = line_segment([0.0, 0.0, 0.0], [3.0, 6.0, 9.0], -1.0, 2.0).unwrap();
    assert_eq!(l.point_at(0.0).unwrap(), [1.0, 2.0, 3.0]);
    let pts = [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
    let p = polyline(&pts, &[0.0, 1.0, 3.0]).unwrap();
    assert_eq!(p.point_at(2.0).unwrap(), [1.0, 0.5, 0.0]);
    assert!(polyline(&pts, &[0.0, 1.0, 1.0]).is_err());
    assert!(polyline(&pts[..1], &[0.0]).is_err());
    assert!(line_segment([0.0; 3], [1.0; 3], 1.0, 1.0).is_err());
}

/// A full circle closes exactly and uses four 90-degree segments (A7.1); a 360.0-degree
/// sweep converted to radians does not earn a fifth; more than a turn is refused.
#[test]
fn full_circle() {
    let deg = std::f64::consts::PI / 180.0;
    let (c, map) = conic_arc(
        ConicKind::Elliptic,
        [0.0; 3],
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        0.0,
        360.0 * deg,
    )
    .unwrap();
    assert_eq!(map.segments(), 4);
    let pts = c.control_points();
    assert_eq!(pts[0], pts[8]);
    let w = c.weights().unwrap();
    assert!((w[1] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    assert!(
        conic_arc(
            ConicKind::Elliptic,
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            0.0,
            7.0
        )
        .is_err()
    );
    assert!(
        conic_arc(
            ConicKind::Hyperbolic,
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            0.0,
            800.0
        )
        .is_err()
    );
    assert!(
        conic_arc(
            ConicKind::Elliptic,
            [f64::NAN, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            0.0,
            1.0
        )
        .is_err()
    );
}

/// A sphere's latitude beyond the poles and a cone at 90 degrees are refused.
#[test]
fn quadric_bounds() {
    let f = Frame {
        origin: [0.0; 3],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    };
    assert!(sweep::sphere(&f, 1.0, (0.0, 1.0), (-2.0, 0.0)).is_err());
    assert!(sweep::cone(&f, 1.0, std::f64::consts::FRAC_PI_2, (0.0, 1.0), (0.0, 1.0)).is_err());
    let skew = Frame {
        x: [1.0, 0.1, 0.0],
        ..f
    };
    assert!(sweep::cylinder(&skew, 1.0, (0.0, 1.0), (0.0, 1.0)).is_err());
}
