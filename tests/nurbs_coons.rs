//! Coons patches (NURBS Book 10.5): the patch built on common bases is checked against the
//! Coons formula evaluated directly from the four boundary curves,
//! `S = (1-v) C0(u) + v C1(u) + (1-u) D0(v) + u D1(v) - bilinear(corners)`, and reproduces
//! its boundaries within 1e-12.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nurbsx::nurbs::coons::coons;
use nurbsx::nurbs::{NurbsCurve, Point3};

fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    std::array::from_fn(|k| (1.0 - t) * a[k] + t * b[k])
}

fn dist(a: Point3, b: Point3) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn coons_patch_matches_the_formula_and_its_boundaries() {
    let (p00, p10, p01, p11) = (
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 1.0],
        [0.0, 3.0, -1.0],
        [4.0, 3.0, 2.0],
    );
    // C0 = S(u, 0): cubic with two interior knots; C1 = S(u, 1): quadratic on [2, 5];
    // D0 = S(0, v): a line; D1 = S(1, v): cubic on [0, 1] with one interior knot.
    let c0 = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 0.3, 0.7, 1., 1., 1., 1.],
        vec![
            p00,
            [1., -1., 0.],
            [2., 1., 3.],
            [3., -1., 0.],
            [3.5, 0.5, 1.],
            p10,
        ],
        None,
    )
    .unwrap();
    let c1 = NurbsCurve::new(
        2,
        vec![2., 2., 2., 3.5, 5., 5., 5.],
        vec![p01, [1., 4., 0.], [3., 2., 1.], p11],
        None,
    )
    .unwrap();
    let d0 = NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![p00, p01], None).unwrap();
    let d1 = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.],
        vec![p10, [5., 1., 1.], [3., 1.5, 0.], [5., 2., 2.], p11],
        None,
    )
    .unwrap();
    let s = coons(&c0, &c1, &d0, &d1, 0.0).unwrap();
    assert_eq!((s.degree_u(), s.degree_v()), (3, 3));
    let at = |c: &NurbsCurve, t: f64| {
        let (a, b) = c.domain();
        c.point_at(a + (b - a) * t).unwrap()
    };
    let mut worst: f64 = 0.0;
    for i in 0..=20 {
        for j in 0..=20 {
            let (u, v) = (f64::from(i) / 20.0, f64::from(j) / 20.0);
            let r1 = lerp(at(&c0, u), at(&c1, u), v);
            let r2 = lerp(at(&d0, v), at(&d1, v), u);
            let t = lerp(lerp(p00, p10, u), lerp(p01, p11, u), v);
            let want: Point3 = std::array::from_fn(|k| r1[k] + r2[k] - t[k]);
            let got = s.point_at(u, v).unwrap();
            worst = worst.max(dist(got, want));
        }
    }
    assert!(
        worst <= 1e-12,
        "largest deviation from the Coons formula {worst:e}"
    );
    for i in 0..=100 {
        let t = f64::from(i) / 100.0;
        for (got, want) in [
            (s.point_at(t, 0.0).unwrap(), at(&c0, t)),
            (s.point_at(t, 1.0).unwrap(), at(&c1, t)),
            (s.point_at(0.0, t).unwrap(), at(&d0, t)),
            (s.point_at(1.0, t).unwrap(), at(&d1, t)),
        ] {
            assert!(dist(got, want) <= 1e-12, "t = {t}: {got:?} vs {want:?}");
        }
    }
    // Corners that do not meet, and rational boundaries, are refused.
    let moved = NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![[0., 0., 1e-3], p01], None).unwrap();
    assert!(coons(&c0, &c1, &moved, &d1, 1e-6).is_err());
    assert!(coons(&c0, &c1, &moved, &d1, 1e-2).is_ok());
    let rational = NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![p00, p01], Some(vec![1., 2.]));
    assert!(coons(&c0, &c1, &rational.unwrap(), &d1, 0.0).is_err());
}
