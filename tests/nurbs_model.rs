//! Model-level checks that need no algorithm beyond evaluation: the random generators
//! produce valid geometry, the domain rule, and point evaluation against an independent
//! method (de Boor's algorithm, NURBS Book eq. 5.x / seed 000 section 2-29, evaluated in
//! homogeneous space).

mod common;

use common::{Ends, arb_curve, arb_surface, dist};
use nurbsx::nurbs::{Hpoint, NurbsCurve};
use proptest::prelude::*;

/// De Boor's algorithm on homogeneous poles: an evaluation independent of A2.2 basis funs.
fn de_boor(c: &NurbsCurve, u: f64) -> [f64; 3] {
    let p = c.degree();
    let k = c.knots();
    let (_, end) = c.domain();
    let n = c.num_poles();
    // Span: last l in p..n with k[l] <= u (< k[l+1] unless at the end).
    let mut l = p;
    while l + 1 < n && (k[l + 1] <= u) && !(u == end && k[l + 1] == end) {
        l += 1;
    }
    let h = c.homogeneous();
    let mut d: Vec<Hpoint> = (0..=p).map(|j| h[j + l - p]).collect();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = j + l - p;
            let a = (u - k[i]) / (k[i + p + 1 - r] - k[i]);
            let prev = d[j - 1];
            for (x, y) in d[j].iter_mut().zip(prev) {
                *x = (1.0 - a) * y + a * *x;
            }
        }
    }
    [d[p][0] / d[p][3], d[p][1] / d[p][3], d[p][2] / d[p][3]]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn point_at_matches_de_boor(c in arb_curve(6, true, Ends::Any), f in 0.0f64..=1.0) {
        let (a, b) = c.domain();
        let u = a + (b - a) * f;
        let ours = c.point_at(u).unwrap();
        let theirs = de_boor(&c, u);
        let size = common::bbox_diagonal(c.control_points());
        prop_assert!(dist(ours, theirs) <= 1e-12 * size, "{:?} vs {:?}", ours, theirs);
    }

    #[test]
    fn surfaces_evaluate_inside_their_domain(s in arb_surface(4, true, Ends::Any)) {
        let ((u0, u1), (v0, v1)) = s.domain();
        prop_assert!(s.point_at(u0, v0).is_ok() && s.point_at(u1, v1).is_ok());
        prop_assert!(s.point_at(u1 + (u1 - u0), v0).is_err());
    }
}

#[test]
fn unclamped_domain_is_up_to_un_plus_1() {
    // pitfalls.md A.1: cubic, 4 poles, knots 0..7 -> domain [3, 4], not [0, 7].
    let c = NurbsCurve::new(
        3,
        (0..8).map(f64::from).collect(),
        vec![[0., 0., 0.], [1., 2., 0.], [3., 2., 0.], [4., 0., 0.]],
        None,
    )
    .unwrap();
    assert_eq!(c.domain(), (3.0, 4.0));
    assert!(c.point_at(2.9).is_err());
    // Uniform cubic B-spline at the span start: (P0 + 4 P1 + P2) / 6.
    let p = c.point_at(3.0).unwrap();
    assert!(dist(p, [(0. + 4. + 3.) / 6., (0. + 8. + 2.) / 6., 0.]) < 1e-15);
    // And the end value is the limit from the left: (P1 + 4 P2 + P3) / 6.
    let p = c.point_at(4.0).unwrap();
    assert!(dist(p, [(1. + 12. + 4.) / 6., (2. + 8.) / 6., 0.]) < 1e-15);
}
