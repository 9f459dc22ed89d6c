//! Global interpolation (A9.1): the NURBS Book example 9.1 parameters and knots by hand, and
//! the interpolant through random points at every method and degree 1..5 to 1e-12 of the
//! data size; coincident points and overlarge inputs are refused.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nurbsx::nurbs::fit::{ParamMethod, averaged_knots, interpolate, parameters};

#[test]
fn example_9_1_parameters_and_knots() {
    let q = [
        [0., 0., 0.],
        [3., 4., 0.],
        [-1., 4., 0.],
        [-4., 0., 0.],
        [-4., -3., 0.],
    ];
    // Chords 5, 4, 5, 3: total 17.
    let t = parameters(&q, ParamMethod::ChordLength).unwrap();
    let want = [0.0, 5.0 / 17.0, 9.0 / 17.0, 14.0 / 17.0, 1.0];
    assert!(
        t.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-15),
        "{t:?}"
    );
    let u = averaged_knots(&t, 3);
    let want = [0., 0., 0., 0., 28.0 / 51.0, 1., 1., 1., 1.];
    assert!(
        u.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-15),
        "{u:?}"
    );
    let c = parameters(&q, ParamMethod::Centripetal).unwrap();
    let s = 5f64.sqrt() * 2.0 + 2.0 + 3f64.sqrt();
    assert!((c[1] - 5f64.sqrt() / s).abs() < 1e-15);
    let un = parameters(&q, ParamMethod::Uniform).unwrap();
    assert_eq!(un, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
}

#[test]
fn the_interpolant_passes_through_every_point() {
    // A deterministic scatter (a linear congruential sequence) of 40 points.
    let mut seed: u64 = 12345;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
    };
    let q: Vec<[f64; 3]> = (0..40).map(|_| [next(), next(), next()]).collect();
    let size = 20.0;
    for method in [
        ParamMethod::Uniform,
        ParamMethod::ChordLength,
        ParamMethod::Centripetal,
    ] {
        let t = parameters(&q, method).unwrap();
        for p in 1..=5 {
            let c = interpolate(&q, p, method, 3).unwrap();
            for (tk, qk) in t.iter().zip(&q) {
                let got = c.point_at(*tk).unwrap();
                let err = (0..3).map(|k| (got[k] - qk[k]).abs()).fold(0.0, f64::max);
                assert!(err <= 1e-12 * size, "{method:?} p={p}: {err:e}");
            }
        }
    }
    let mut dup = q.clone();
    dup[5] = dup[4];
    assert!(interpolate(&dup, 3, ParamMethod::ChordLength, 3).is_err());
    assert!(interpolate(&q[..3], 3, ParamMethod::Uniform, 3).is_err());
    let many = vec![[0.0; 3]; nurbsx::nurbs::fit::MAX_FIT_POINTS + 1];
    assert!(interpolate(&many, 3, ParamMethod::Uniform, 3).is_err());
}
