//! Affine transforms, reversal, reparameterisation and isoparametric curves, each checked
//! pointwise against the untransformed geometry.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{Ends, arb_curve, arb_surface, bbox_diagonal, dist};
use nurbsx::nurbs::transform::{Affine, apply};
use nurbsx::nurbs::{NurbsCurve, Point3};
use proptest::prelude::*;

fn arb_affine() -> impl Strategy<Value = Affine> {
    prop::array::uniform3(prop::array::uniform4(-3.0f64..3.0))
}

/// `n + 1` parameters evenly over `[a, b]`, ends exact.
fn grid(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| {
            if i == n {
                b
            } else {
                a + (b - a) * i as f64 / n as f64
            }
        })
        .collect()
}

fn norm_inf(m: &Affine) -> f64 {
    m.iter().flatten().fold(1.0f64, |x, y| x.max(y.abs()))
}

fn size_of(points: &[Point3]) -> f64 {
    bbox_diagonal(points).max(points.iter().flatten().fold(1.0f64, |x, y| x.max(y.abs())))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn curve_transform_commutes_with_evaluation(c in arb_curve(5, true, Ends::Any), m in arb_affine()) {
        let t = c.transform(&m).unwrap();
        prop_assert_eq!(t.domain(), c.domain());
        prop_assert_eq!(t.weights(), c.weights());
        let (a, b) = c.domain();
        let scale = size_of(c.control_points()) * norm_inf(&m);
        for u in grid(a, b, 200) {
            let lhs = t.point_at(u).unwrap();
            let rhs = apply(&m, c.point_at(u).unwrap());
            prop_assert!(dist(lhs, rhs) <= 1e-12 * scale, "{:?} vs {:?}", lhs, rhs);
        }
    }

    #[test]
    fn surface_transform_commutes_with_evaluation(s in arb_surface(3, true, Ends::Any), m in arb_affine()) {
        let t = s.transform(&m).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        let scale = size_of(s.control_points().as_slice()) * norm_inf(&m);
        for u in grid(u0, u1, 20) {
            for v in grid(v0, v1, 20) {
                let lhs = t.point_at(u, v).unwrap();
                let rhs = apply(&m, s.point_at(u, v).unwrap());
                prop_assert!(dist(lhs, rhs) <= 1e-12 * scale);
            }
        }
    }

    #[test]
    fn reverse_mirrors_the_parameter(c in arb_curve(5, true, Ends::Any)) {
        let r = c.reverse().unwrap();
        let (a, b) = c.domain();
        prop_assert_eq!(r.domain(), (a, b));
        let size = size_of(c.control_points());
        for u in grid(a, b, 300) {
            let mirrored = (a + b - u).clamp(a, b);
            // The mirrored parameter is rounded; compare with a tolerance scaled by the
            // size (the curve is Lipschitz in u, and the rounding is ~1 ulp of |a| + |b|).
            let d = dist(r.point_at(mirrored).unwrap(), c.point_at(u).unwrap());
            prop_assert!(d <= 1e-9 * size, "u={} d={:e}", u, d);
        }
        // The ends map exactly (no parameter rounding there).
        prop_assert!(dist(c.point_at(a).unwrap(), r.point_at(b).unwrap()) <= 1e-12 * size);
        prop_assert!(dist(c.point_at(b).unwrap(), r.point_at(a).unwrap()) <= 1e-12 * size);
        // Twice: poles and weights bit-exact, domain bit-exact, knots to rounding.
        let rr = r.reverse().unwrap();
        prop_assert_eq!(rr.control_points(), c.control_points());
        prop_assert_eq!(rr.weights(), c.weights());
        prop_assert_eq!(rr.domain(), c.domain());
        let span = (b - a).abs() + a.abs() + b.abs();
        // Each knot k goes to a + b - k and back: rounded relative to the larger of the
        // domain and |k| itself (knots of an unclamped curve can lie far outside the domain).
        for (x, y) in rr.knots().iter().zip(c.knots()) {
            prop_assert!(
                (x - y).abs() <= 4.0 * f64::EPSILON * (span + y.abs()),
                "{} vs {}", x, y
            );
        }
    }

    #[test]
    fn reparameterize_keeps_the_point_set(
        c in arb_curve(5, true, Ends::Any),
        c0 in -100.0f64..100.0,
        len in 1e-3f64..1e3,
    ) {
        let d0 = c0 + len;
        let r = c.reparameterize(c0, d0).unwrap();
        prop_assert_eq!(r.domain(), (c0, d0));
        prop_assert_eq!(r.control_points(), c.control_points());
        let (a, b) = c.domain();
        let size = size_of(c.control_points());
        for i in 0..=200 {
            let s = f64::from(i) / 200.0;
            let u = (a + (b - a) * s).clamp(a, b);
            let v = (c0 + (d0 - c0) * s).clamp(c0, d0);
            let dd = dist(r.point_at(v).unwrap(), c.point_at(u).unwrap());
            prop_assert!(dd <= 1e-9 * size, "s={} d={:e}", s, dd);
        }
    }

    /// `swap_uv` exchanges the parameters: `S'(u, v) = S(v, u)` and `S'_u = S_v`,
    /// `S'_v = S_u`, `S'_uv = S_uv` (evaluated independently on each surface, NURBS Book
    /// A4.4); swapping twice gives the same surface, bit for bit.
    #[test]
    fn swap_uv_exchanges_the_parameters(s in arb_surface(3, true, Ends::Any)) {
        let t = s.swap_uv().unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        prop_assert_eq!(t.domain(), ((v0, v1), (u0, u1)));
        prop_assert_eq!(t.swap_uv().unwrap(), s.clone());
        let size = size_of(s.control_points().as_slice());
        for u in grid(u0, u1, 9) {
            for v in grid(v0, v1, 9) {
                let a = s.derivatives(u, v, 2).unwrap();
                let b = t.derivatives(v, u, 2).unwrap();
                let pairs = [
                    (a[0][0], b[0][0], 1e-12),
                    (a[1][0], b[0][1], 1e-9),
                    (a[0][1], b[1][0], 1e-9),
                    (a[1][1], b[1][1], 1e-9),
                ];
                for (p, q, tol) in pairs {
                    let scale = size.max(p.iter().fold(0.0f64, |m, x| m.max(x.abs())));
                    prop_assert!(dist(p, q) <= tol * scale, "{:?} {:?}", p, q);
                }
            }
        }
    }

    #[test]
    fn surface_reverse_and_reparameterize(s in arb_surface(3, true, Ends::Any)) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let ru = s.reverse_u().unwrap();
        let rv = s.reverse_v().unwrap();
        let pu = s.reparameterize_u(0.0, 1.0).unwrap();
        let pv = s.reparameterize_v(-2.0, 3.0).unwrap();
        prop_assert_eq!(ru.domain(), s.domain());
        prop_assert_eq!(pu.domain().0, (0.0, 1.0));
        prop_assert_eq!(pv.domain().1, (-2.0, 3.0));
        let size = size_of(s.control_points().as_slice());
        for (i, u) in grid(u0, u1, 12).into_iter().enumerate() {
            for (j, v) in grid(v0, v1, 12).into_iter().enumerate() {
                let p = s.point_at(u, v).unwrap();
                let su = f64::from(i as u32) / 12.0;
                let sv = f64::from(j as u32) / 12.0;
                let checks = [
                    ru.point_at((u0 + u1 - u).clamp(u0, u1), v).unwrap(),
                    rv.point_at(u, (v0 + v1 - v).clamp(v0, v1)).unwrap(),
                    pu.point_at(su, v).unwrap(),
                    pv.point_at(u, -2.0 + 5.0 * sv).unwrap(),
                ];
                for q in checks {
                    prop_assert!(dist(p, q) <= 1e-9 * size);
                }
            }
        }
    }

    #[test]
    fn iso_curves_match_surface_points(s in arb_surface(4, true, Ends::Any), fu in 0.0f64..=1.0, fv in 0.0f64..=1.0) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let u = (u0 + (u1 - u0) * fu).clamp(u0, u1);
        let v = (v0 + (v1 - v0) * fv).clamp(v0, v1);
        let cu = s.iso_u(u).unwrap();
        let cv = s.iso_v(v).unwrap();
        prop_assert_eq!(cu.degree(), s.degree_v());
        prop_assert_eq!(cv.degree(), s.degree_u());
        prop_assert_eq!(cu.is_rational(), s.is_rational());
        let size = size_of(s.control_points().as_slice());
        for t in grid(v0, v1, 50) {
            prop_assert!(dist(cu.point_at(t).unwrap(), s.point_at(u, t).unwrap()) <= 1e-12 * size);
        }
        for t in grid(u0, u1, 50) {
            prop_assert!(dist(cv.point_at(t).unwrap(), s.point_at(t, v).unwrap()) <= 1e-12 * size);
        }
        prop_assert!(s.iso_u(u1 + 1.0).is_err());
        prop_assert!(s.iso_v(f64::NAN).is_err());
    }

    /// At the knots, where a knot of multiplicity `p` or a clamped end makes one basis
    /// function 1 (NURBS Book eq. 3.10), the isocurves still run on the surface, and at a
    /// clamped end their poles and weights are the net's boundary row exactly.
    #[test]
    fn iso_curves_at_knots_match_surface_points(
        s in arb_surface(4, true, Ends::Any),
        ku in any::<prop::sample::Index>(),
        kv in any::<prop::sample::Index>(),
    ) {
        let ((u0, u1), (v0, v1)) = s.domain();
        let u = s.knots_u()[ku.index(s.knots_u().len())].clamp(u0, u1);
        let v = s.knots_v()[kv.index(s.knots_v().len())].clamp(v0, v1);
        let size = size_of(s.control_points().as_slice());
        let (cu, cv) = (s.iso_u(u).unwrap(), s.iso_v(v).unwrap());
        for t in grid(v0, v1, 50) {
            prop_assert!(dist(cu.point_at(t).unwrap(), s.point_at(u, t).unwrap()) <= 1e-12 * size);
        }
        for t in grid(u0, u1, 50) {
            prop_assert!(dist(cv.point_at(t).unwrap(), s.point_at(t, v).unwrap()) <= 1e-12 * size);
        }
        let (p, q, net) = (s.degree_u(), s.degree_v(), s.control_points());
        let (ku, kv) = (s.knots_u(), s.knots_v());
        if ku[..=p].iter().all(|&k| k == u0) && ku[ku.len() - p - 1..].iter().all(|&k| k == u1) {
            let (first, last) = (s.iso_u(u0).unwrap(), s.iso_u(u1).unwrap());
            for j in 0..net.nv() {
                prop_assert_eq!(first.control_points()[j], *net.get(0, j));
                prop_assert_eq!(first.weight(j), s.weight(0, j));
                prop_assert_eq!(last.control_points()[j], *net.get(net.nu() - 1, j));
                prop_assert_eq!(last.weight(j), s.weight(net.nu() - 1, j));
            }
        }
        if kv[..=q].iter().all(|&k| k == v0) {
            let first = s.iso_v(v0).unwrap();
            for i in 0..net.nu() {
                prop_assert_eq!(first.control_points()[i], *net.get(i, 0));
                prop_assert_eq!(first.weight(i), s.weight(i, 0));
            }
        }
    }
}

#[test]
fn reverse_twice_is_bit_exact_on_dyadic_knots() {
    let c = NurbsCurve::new(
        3,
        vec![0.5, 0.75, 1., 1.25, 2., 2.5, 2.5, 3., 3.25],
        vec![
            [0., 0., 0.],
            [1., 2., 0.],
            [2., -1., 1.],
            [3., 0., 0.],
            [4., 1., 2.],
        ],
        Some(vec![1., 2., 0.5, 1., 3.]),
    )
    .unwrap();
    let rr = c.reverse().unwrap().reverse().unwrap();
    assert_eq!(rr, c);
}

#[test]
fn transform_keeps_2d_when_planar_and_refuses_nan() {
    let c = NurbsCurve::with_dimension(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![[0., 0., 0.], [1., 1., 0.], [2., 0., 0.]],
        None,
        2,
    )
    .unwrap();
    let rot: Affine = [[0., -1., 0., 1.], [1., 0., 0., 2.], [0., 0., 1., 0.]];
    assert_eq!(c.transform(&rot).unwrap().dimension(), 2);
    let lift: Affine = [[1., 0., 0., 0.], [0., 1., 0., 0.], [0., 0., 1., 5.]];
    assert_eq!(c.transform(&lift).unwrap().dimension(), 3);
    let bad: Affine = [[f64::NAN, 0., 0., 0.], [0., 1., 0., 0.], [0., 0., 1., 0.]];
    assert!(c.transform(&bad).is_err());
    assert!(c.reparameterize(1.0, 1.0).is_err());
    assert!(c.reparameterize(2.0, f64::INFINITY).is_err());
}
