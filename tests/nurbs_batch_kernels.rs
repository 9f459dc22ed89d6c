//! The fast batch kernels (span lookup, register A2.2 for degrees 1-5, two-point surface
//! kernel, per-span Bezier sampler) against the straightforward single-point evaluation
//! (`point_at`: A2.1 binary search, A2.2, A4.1 / A4.3), over random rational and polynomial,
//! clamped and unclamped curves and surfaces of degrees 1..=9 with interior multiplicities up
//! to the degree, at random parameters, at every knot, one ulp either side of every knot and
//! at the domain ends.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{Ends, arb_curve, arb_knots, bbox_diagonal, norm, sub};
use nurbsx::nurbs::batch::{CurveEvaluator, SurfaceEvaluator};
use nurbsx::nurbs::{GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};
use proptest::prelude::*;

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// Random parameters in `[a, b]`, the ends, every knot in the domain and its neighbours one
/// ulp away (clamped into the domain).
fn params(a: f64, b: f64, knots: &[f64], n: usize, seed: &mut u64) -> Vec<f64> {
    let mut t: Vec<f64> = (0..n).map(|_| a + (b - a) * lcg(seed)).collect();
    t.extend([a, b]);
    for &k in knots.iter().filter(|&&k| k >= a && k <= b) {
        t.push(k);
        // Bit neighbours (away from and towards zero); at 0 one of them is not a number.
        for n in [k.to_bits().wrapping_add(1), k.to_bits().wrapping_sub(1)] {
            let n = f64::from_bits(n);
            if n.is_finite() {
                t.push(n.clamp(a, b));
            }
        }
    }
    t
}

fn bits(p: Point3) -> [u64; 3] {
    p.map(f64::to_bits)
}

fn polynomial(c: &NurbsCurve) -> NurbsCurve {
    NurbsCurve::new(
        c.degree(),
        c.knots().to_vec(),
        c.control_points().to_vec(),
        None,
    )
    .unwrap()
}

/// A random surface with the same degree `1..=max` in u and v (the two-point kernel's case),
/// 2-5 extra poles each way.
fn arb_surface_equal_degrees(max: usize) -> impl Strategy<Value = NurbsSurface> {
    (1..=max, 0usize..5, 0usize..5, any::<bool>())
        .prop_flat_map(|(p, eu, ev, rational)| {
            let (nu, nv) = (p + 1 + eu, p + 1 + ev);
            (
                Just((p, nu, nv, rational)),
                arb_knots(p, nu, Ends::Any),
                arb_knots(p, nv, Ends::Any),
                prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), nu * nv),
                prop::collection::vec(0.2f64..5.0, nu * nv),
            )
        })
        .prop_filter_map(
            "valid surface",
            |((p, nu, nv, rational), ku, kv, pts, w)| {
                let points = Grid::from_u_major(nu, nv, pts)?;
                let weights = if rational {
                    Some(Grid::from_u_major(nu, nv, w)?)
                } else {
                    None
                };
                NurbsSurface::new(p, p, ku, kv, points, weights).ok()
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(160))]

    /// `points` (span lookup + register A2.2), `points_sorted` (with its four-parameter
    /// lane kernel) and `point` equal `point_at` bit for bit, in random and sorted order.
    #[test]
    fn curve_kernels_equal_point_at_bit_for_bit(
        c in arb_curve(9, true, Ends::Any), seed in any::<u64>(), rational in any::<bool>()
    ) {
        let c = if rational { c } else { polynomial(&c) };
        let mut seed = seed;
        let (a, b) = c.domain();
        let us = params(a, b, c.knots(), 60, &mut seed);
        let ev = CurveEvaluator::new(&c);
        let mut out = Vec::new();
        ev.points(&us, &mut out).unwrap();
        prop_assert_eq!(out.len(), us.len());
        for (&u, &p) in us.iter().zip(&out) {
            let want = c.point_at(u).unwrap();
            prop_assert_eq!(bits(p), bits(want), "u = {}", u);
            prop_assert_eq!(bits(ev.point(u).unwrap()), bits(want), "point u = {}", u);
        }
        let mut sorted = us.clone();
        sorted.sort_by(f64::total_cmp);
        ev.points_sorted(&sorted, &mut out).unwrap();
        for (&u, &p) in sorted.iter().zip(&out) {
            prop_assert_eq!(bits(p), bits(c.point_at(u).unwrap()), "sorted u = {}", u);
        }
        // `points_sorted` on unsorted input (its four-at-a-time path must notice), and on
        // runs that straddle knots: every third parameter repeated, in descending order.
        let mut mixed = us.clone();
        mixed.extend(sorted.iter().rev().step_by(3));
        ev.points_sorted(&mixed, &mut out).unwrap();
        prop_assert_eq!(out.len(), mixed.len());
        for (&u, &p) in mixed.iter().zip(&out) {
            prop_assert_eq!(bits(p), bits(c.point_at(u).unwrap()), "unsorted u = {}", u);
        }
    }

    /// The per-span Bezier sampler equals `point_at` within `1e-14` of the model size (the
    /// diagonal of the control points' bounding box), sorted and unsorted, rational and
    /// polynomial, clamped and unclamped, degrees 1..=9; and the run logic puts every
    /// parameter at a knot in the span A2.1 gives (a wrong span would be off by far more).
    #[test]
    fn bezier_sampler_within_1e14_of_model_size(
        c in arb_curve(9, true, Ends::Any), seed in any::<u64>(), rational in any::<bool>()
    ) {
        let c = if rational { c } else { polynomial(&c) };
        let mut seed = seed;
        let (a, b) = c.domain();
        let us = params(a, b, c.knots(), 200, &mut seed);
        let mut sorted = us.clone();
        sorted.sort_by(f64::total_cmp);
        let size = bbox_diagonal(c.control_points());
        let ev = CurveEvaluator::new(&c);
        let mut out = Vec::new();
        for input in [&sorted, &us] {
            ev.points_sorted_bezier(input, &mut out).unwrap();
            prop_assert_eq!(out.len(), input.len());
            for (&u, &got) in input.iter().zip(&out) {
                let want = c.point_at(u).unwrap();
                let err = norm(sub(got, want));
                prop_assert!(err <= 1e-14 * size, "p = {}, u = {}: {:?} vs {:?}, err {:e} of {}",
                    c.degree(), u, got, want, err / size, size);
            }
        }
    }

    /// Surfaces of equal degrees (register A2.2 and the two-point kernel for degrees 1-5)
    /// and of unequal degrees: `points` and `point` equal `point_at` bit for bit, for odd and
    /// even batch lengths (the pair loop's remainder).
    #[test]
    fn surface_kernels_equal_point_at_bit_for_bit(
        s in arb_surface_equal_degrees(9), seed in any::<u64>(), odd in any::<bool>()
    ) {
        let mut seed = seed;
        let ((u0, u1), (v0, v1)) = s.domain();
        let us = params(u0, u1, s.knots_u(), 20, &mut seed);
        let vs = params(v0, v1, s.knots_v(), 20, &mut seed);
        let mut uvs: Vec<[f64; 2]> = us.iter().zip(vs.iter().cycle()).map(|(&u, &v)| [u, v]).collect();
        uvs.extend(vs.iter().zip(us.iter().cycle()).map(|(&v, &u)| [u, v]));
        uvs.extend((0..40).map(|_| [u0 + (u1 - u0) * lcg(&mut seed), v0 + (v1 - v0) * lcg(&mut seed)]));
        if odd == (uvs.len() % 2 == 0) {
            uvs.pop();
        }
        let ev = SurfaceEvaluator::new(&s);
        let mut out = Vec::new();
        ev.points(&uvs, &mut out).unwrap();
        prop_assert_eq!(out.len(), uvs.len());
        for (&[u, v], &p) in uvs.iter().zip(&out) {
            let want = s.point_at(u, v).unwrap();
            prop_assert_eq!(bits(p), bits(want), "({}, {}) degree {}", u, v, s.degree_u());
            prop_assert_eq!(bits(ev.point(u, v).unwrap()), bits(want));
        }
    }
}

/// A cubic with knots clustered in one part of the domain (many spans per lookup bucket:
/// the lookup's scan and its binary-search fallback) and a double interior knot.
fn clustered_cubic() -> NurbsCurve {
    let mut knots = vec![0.0; 4];
    knots.extend((1..=30).map(|i| f64::from(i) * 1e-4));
    knots.extend([0.5, 0.5, 0.75]);
    knots.extend([1.0; 4]);
    let n = knots.len() - 4;
    let pts = (0..n)
        .map(|i| {
            let t = i as f64;
            [t, (t * 0.7).sin(), (t * 0.3).cos()]
        })
        .collect();
    let w = (0..n)
        .map(|i| 1.0 + 0.5 * ((i as f64) * 1.3).sin())
        .collect();
    NurbsCurve::new(3, knots, pts, Some(w)).unwrap()
}

#[test]
fn clustered_knots_take_the_a21_span() {
    let c = clustered_cubic();
    let mut seed = 3;
    let us = params(0.0, 1.0, c.knots(), 3000, &mut seed);
    let ev = CurveEvaluator::new(&c);
    let mut out = Vec::new();
    ev.points(&us, &mut out).unwrap();
    for (&u, &p) in us.iter().zip(&out) {
        assert_eq!(bits(p), bits(c.point_at(u).unwrap()), "u = {u}");
    }
    let mut sorted = us.clone();
    sorted.sort_by(f64::total_cmp);
    let size = bbox_diagonal(c.control_points());
    ev.points_sorted_bezier(&sorted, &mut out).unwrap();
    for (&u, &p) in sorted.iter().zip(&out) {
        assert!(
            norm(sub(p, c.point_at(u).unwrap())) <= 1e-14 * size,
            "u = {u}"
        );
    }
}

#[test]
fn out_of_domain_and_nan_are_errors_with_earlier_values_kept() {
    let c = clustered_cubic();
    let ev = CurveEvaluator::new(&c);
    let mut out = Vec::new();
    for bad in [f64::NAN, -0.5, 1.5, f64::INFINITY] {
        for call in 0..3 {
            let us = [0.1, 0.2, 0.3, bad, 0.4];
            let r = match call {
                0 => ev.points(&us, &mut out),
                1 => ev.points_sorted(&us, &mut out),
                _ => ev.points_sorted_bezier(&us, &mut out),
            };
            assert!(
                matches!(r, Err(GeometryError::OutOfDomain { .. })),
                "{call}: {r:?}"
            );
            assert_eq!(out.len(), 3, "{call}: values before {bad} are kept");
        }
    }
    // The two-point surface kernel: a bad second point of a pair keeps the first.
    let s = NurbsSurface::new(
        3,
        3,
        vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.],
        vec![0., 0., 0., 0., 1., 1., 1., 1.],
        Grid::from_fn(5, 4, |i, j| [i as f64, j as f64, (i * j) as f64]),
        Some(Grid::from_fn(5, 4, |i, j| 1.0 + 0.1 * (i + j) as f64)),
    )
    .unwrap();
    let ev = SurfaceEvaluator::new(&s);
    for bad in [[0.5, f64::NAN], [2.0, 0.5], [f64::NEG_INFINITY, 0.5]] {
        for at in 0..4 {
            let mut uvs = vec![[0.1, 0.2], [0.3, 0.4], [0.5, 0.6], [0.7, 0.8]];
            uvs[at] = bad;
            let r = ev.points(&uvs, &mut out);
            assert!(matches!(r, Err(GeometryError::OutOfDomain { .. })), "{r:?}");
            assert_eq!(out.len(), at, "bad point at {at}");
            for (&[u, v], &p) in uvs.iter().zip(&out) {
                assert_eq!(bits(p), bits(s.point_at(u, v).unwrap()));
            }
        }
    }
}
