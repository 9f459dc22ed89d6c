//! Point inversion and pcurves by projection, checked against closed forms: the distance of
//! a point to a sphere is `| |P - O| - r |`, a circle in a plane stays at its radius, an
//! iso-line of a surface has a constant parameter, a generator of a cylinder lies at one
//! angle. Never against the projection's own output.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{dist, norm, sub};
use nurbsx::nurbs::conic::{ConicKind, conic_arc, line_segment};
use nurbsx::nurbs::project::{invert_surface, pcurve_by_projection};
use nurbsx::nurbs::sweep::{self, Frame};
use nurbsx::nurbs::{NurbsCurve, NurbsSurface, Point3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

const Z: Frame = Frame {
    origin: [1.0, -2.0, 0.5],
    x: [1.0, 0.0, 0.0],
    y: [0.0, 1.0, 0.0],
    z: [0.0, 0.0, 1.0],
};

/// `|surface(pcurve(t)) - curve(t)|` at 101 parameters none of which is a fitted one
/// (shifted by an irrational fraction of the step).
fn worst_on(surface: &NurbsSurface, curve: &NurbsCurve, pcurve: &NurbsCurve) -> f64 {
    let (a, b) = pcurve.domain();
    (0..=100)
        .map(|i| {
            let t = a + (b - a) * ((i as f64 + 0.5 * std::f64::consts::FRAC_1_SQRT_2) / 101.0);
            let [u, v, _] = pcurve.point_at(t).unwrap();
            let ((u0, u1), (v0, v1)) = surface.domain();
            dist(
                surface.point_at(u.clamp(u0, u1), v.clamp(v0, v1)).unwrap(),
                curve.point_at(t).unwrap(),
            )
        })
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The closest point of a sphere to P is at distance | |P - O| - r | (the sphere's
    /// closed form), on the ray from O through P.
    #[test]
    fn sphere_inversion_matches_the_closed_form(
        lon in -3.0f64..3.0, lat in -1.4f64..1.4, rho in 0.3f64..3.0,
    ) {
        let r = 2.0;
        let (s, _) = sweep::sphere(&Z, r, (-PI, PI), (-FRAC_PI_2, FRAC_PI_2)).unwrap();
        let dir = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
        let p = [Z.origin[0] + rho * r * dir[0], Z.origin[1] + rho * r * dir[1], Z.origin[2] + rho * r * dir[2]];
        let hit = invert_surface(&s, p, None).unwrap();
        let want = (rho * r - r).abs();
        prop_assert!((hit.distance - want).abs() <= 1e-9, "{} vs {}", hit.distance, want);
        let on = s.point_at(hit.u, hit.v).unwrap();
        let radial = sub(on, Z.origin);
        let back = [radial[0] / r, radial[1] / r, radial[2] / r];
        prop_assert!(dist(back, dir) <= 1e-7, "{:?} vs {:?}", back, dir);
    }

    /// A circle lying in a plane patch: its pcurve keeps the circle (every point of
    /// plane(pcurve(t)) at the radius from the centre), within the tolerance asked, checked
    /// off the fitted parameters.
    #[test]
    fn circle_on_a_plane(r in 0.2f64..1.5, t0 in -3.0f64..0.0, sweep_angle in 0.3f64..6.2) {
        let plane = sweep::plane(&Z, (-2.0, 2.5), (-1.7, 2.0)).unwrap();
        let centre = [Z.origin[0] + 0.2, Z.origin[1] + 0.1, Z.origin[2]];
        let (circle, _) = conic_arc(ConicKind::Elliptic, centre, [r, 0.0, 0.0], [0.0, r, 0.0], t0, t0 + sweep_angle).unwrap();
        let tol = 1e-7;
        let (pc, dev) = pcurve_by_projection(&plane, &circle, circle.domain(), tol).unwrap();
        prop_assert_eq!(pc.dimension(), 2);
        prop_assert_eq!(pc.domain(), circle.domain());
        prop_assert!(dev <= tol, "deviation {:e}", dev);
        let worst = worst_on(&plane, &circle, &pc);
        prop_assert!(worst <= 10.0 * tol, "off the fitted parameters: {:e}", worst);
        let (a, b) = pc.domain();
        for i in 0..=20 {
            let t = if i == 20 { b } else { a + (b - a) * i as f64 / 20.0 };
            let [u, v, _] = pc.point_at(t).unwrap();
            let on = plane.point_at(u, v).unwrap();
            prop_assert!((norm(sub(on, centre)) - r).abs() <= 10.0 * tol);
        }
    }
}

/// An iso-line of a bicubic B-spline surface at v = 0.37 projects to v = 0.37 and, on the
/// part [0.2, 0.9] of its range, to u = t.
#[test]
fn iso_line_of_a_bspline_surface() {
    let knots = vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 1.0];
    let poles: Vec<Point3> = (0..5)
        .flat_map(|i| {
            (0..5).map(move |j| {
                let (x, y) = (i as f64 * 0.9, j as f64 * 1.1);
                [x, y, 0.3 * (x * 1.3).sin() * (y * 0.7).cos() + 0.05 * x * y]
            })
        })
        .collect();
    let s = NurbsSurface::new(
        3,
        3,
        knots.clone(),
        knots,
        nurbsx::nurbs::Grid::from_u_major(5, 5, poles).unwrap(),
        None,
    )
    .unwrap();
    let iso = s.iso_v(0.37).unwrap();
    let (pc, dev) = pcurve_by_projection(&s, &iso, (0.2, 0.9), 1e-9).unwrap();
    assert!(dev <= 1e-9, "{dev:e}");
    assert_eq!(pc.domain(), (0.2, 0.9));
    for i in 0..=30 {
        let t = 0.2 + 0.7 * (i as f64 + 0.3) / 31.0;
        let [u, v, _] = pc.point_at(t).unwrap();
        assert!((v - 0.37).abs() <= 1e-8, "v {v} at t {t}");
        assert!((u - t).abs() <= 1e-8, "u {u} at t {t}");
    }
}

/// A generator of a full cylinder at angle 0 lies on the seam: its pcurve keeps one side
/// (u constant at the start or the end of the domain), and a generator at 90 degrees maps to
/// the u of that angle through the cylinder's exact angle map.
#[test]
fn generators_of_a_cylinder_and_its_seam() {
    let r = 1.5;
    let (cyl, map) = sweep::cylinder(&Z, r, (0.0, 2.0 * PI), (-1.0, 3.0)).unwrap();
    let ((u0, u1), _) = cyl.domain();
    let at = |angle: f64, h: f64| -> Point3 {
        [
            Z.origin[0] + r * angle.cos(),
            Z.origin[1] + r * angle.sin(),
            Z.origin[2] + h,
        ]
    };
    for (angle, expected) in [(0.0, None), (FRAC_PI_2, Some(map.u().to_nurbs(FRAC_PI_2)))] {
        let line = line_segment(at(angle, -0.5), at(angle, 2.5), 0.0, 3.0).unwrap();
        let (pc, dev) = pcurve_by_projection(&cyl, &line, (0.0, 3.0), 1e-9).unwrap();
        assert!(dev <= 1e-9, "{dev:e}");
        let us: Vec<f64> = (0..=12)
            .map(|i| pc.point_at(3.0 * i as f64 / 12.0).unwrap()[0])
            .collect();
        let first = us[0];
        assert!(us.iter().all(|u| (u - first).abs() <= 1e-9), "{us:?}");
        match expected {
            None => assert!(
                (first - u0).abs() <= 1e-9 || (first - u1).abs() <= 1e-9,
                "{first} not on the seam"
            ),
            Some(u) => assert!((first - u).abs() <= 1e-9, "{first} vs {u}"),
        }
        // v follows the height exactly: v(t) = t - 0.5 (the line rises by 1 per unit t).
        for i in 0..=12 {
            let t = 3.0 * (i as f64 + 0.4) / 13.0;
            let v = pc.point_at(t).unwrap()[1];
            assert!((v - (t - 0.5)).abs() <= 1e-8, "v {v} at t {t}");
        }
    }
}

/// A meridian of a sphere from the equator to the north pole: the pole is degenerate (every
/// u gives it), yet the pcurve keeps the meridian's u to the end.
#[test]
fn meridian_through_a_pole() {
    let r = 1.0;
    let (s, map) = sweep::sphere(&Z, r, (-PI, PI), (-FRAC_PI_2, FRAC_PI_2)).unwrap();
    let lon: f64 = 0.7;
    let (meridian, _) = conic_arc(
        ConicKind::Elliptic,
        Z.origin,
        [r * lon.cos(), r * lon.sin(), 0.0],
        [0.0, 0.0, r],
        0.0,
        FRAC_PI_2,
    )
    .unwrap();
    let (pc, dev) = pcurve_by_projection(&s, &meridian, meridian.domain(), 1e-9).unwrap();
    assert!(dev <= 1e-9, "{dev:e}");
    let want = map.u().to_nurbs(lon);
    let (a, b) = pc.domain();
    for i in 0..=10 {
        let t = if i == 10 {
            b
        } else {
            a + (b - a) * i as f64 / 10.0
        };
        let u = pc.point_at(t).unwrap()[0];
        assert!((u - want).abs() <= 1e-8, "u {u} vs {want}");
    }
}

/// A curve that is not on the surface is refused, not fitted.
#[test]
fn a_curve_off_the_surface_is_refused() {
    let plane = sweep::plane(&Z, (-1.0, 1.0), (-1.0, 1.0)).unwrap();
    let line = line_segment([0.0, 0.0, 5.0], [1.0, 0.0, 6.0], 0.0, 1.0).unwrap();
    assert!(pcurve_by_projection(&plane, &line, (0.0, 1.0), 1e-7).is_err());
    // An empty or reversed range too.
    let on = line_segment(Z.origin, [1.5, -2.0, 0.5], 0.0, 1.0).unwrap();
    assert!(pcurve_by_projection(&plane, &on, (0.5, 0.5), 1e-7).is_err());
    assert!(pcurve_by_projection(&plane, &on, (0.0, 1.0), 1e-7).is_ok());
}

/// An arc of a cylinder's parallel that starts on the seam and runs to smaller angles, with
/// a loose tolerance (a file's 1e-2): Newton continued from the previous point is kept in
/// the domain, so the points just across the seam stopped on it (the seam's side of the
/// start) within the tolerance, and the next ones, found by the global search on the other
/// side, made the pcurve jump (refused as a seam crossing). Each point must land at its own
/// angle (through the cylinder's exact angle map), the whole pcurve on the far side.
#[test]
fn an_arc_leaving_the_seam_backwards_takes_the_far_side() {
    let r = 1.5;
    let (cyl, map) = sweep::cylinder(&Z, r, (0.0, 2.0 * PI), (-1.0, 3.0)).unwrap();
    let ((u0, u1), _) = cyl.domain();
    let centre = [Z.origin[0], Z.origin[1], Z.origin[2] + 0.7];
    // Angle -t for t in [0, 2]: x = cos t, y = -sin t.
    let (arc, _) = conic_arc(
        ConicKind::Elliptic,
        centre,
        [r, 0.0, 0.0],
        [0.0, -r, 0.0],
        0.0,
        2.0,
    )
    .unwrap();
    // Short spans near the seam (exact refinement, A5.4), as an intersection curve has: the
    // projected points there are a small fraction of the tolerance apart.
    let fine: Vec<f64> = (1..40).map(|k| 0.005 * k as f64).collect();
    let arc = arc.refine(&fine).unwrap();
    let tol = 1e-2;
    let (pc, dev) = pcurve_by_projection(&cyl, &arc, arc.domain(), tol).unwrap();
    assert!(dev <= tol, "{dev:e}");
    for i in 0..=40 {
        let t = 2.0 * i as f64 / 40.0;
        let u = pc.point_at(t).unwrap()[0];
        assert!(u >= u0 && u <= u1, "u {u} outside [{u0}, {u1}]");
        let want = if i == 0 {
            u1
        } else {
            map.u().to_nurbs(2.0 * PI - t)
        };
        // The fit is within the tolerance on the surface: r du/dangle >= r / 2 here.
        assert!(
            (u - want).abs() * r <= 4.0 * tol,
            "t {t}: u {u}, the angle's u {want}"
        );
    }
}

/// A point just across the seam of a closed surface from the seam's sample (which stands
/// for both ends of the domain, being one point) is found at its own parameters.
#[test]
fn a_point_just_across_the_seam_is_found() {
    let r = 1.5;
    let (cyl, map) = sweep::cylinder(&Z, r, (0.0, 2.0 * PI), (-1.0, 3.0)).unwrap();
    for angle in [-1e-3, -1e-7, 1e-3, 1e-7] {
        let p = [
            Z.origin[0] + r * f64::cos(angle),
            Z.origin[1] + r * f64::sin(angle),
            Z.origin[2] + 1.3,
        ];
        let hit = invert_surface(&cyl, p, None).unwrap();
        assert!(
            hit.distance <= 1e-12,
            "angle {angle}: distance {:e}",
            hit.distance
        );
        let want = map.u().to_nurbs(angle.rem_euclid(2.0 * PI));
        assert!(
            (hit.u - want).abs() <= 1e-9,
            "angle {angle}: u {} vs {want}",
            hit.u
        );
    }
}
