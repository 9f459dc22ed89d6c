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
            let c = interpolate(&q, p, method, 3).unwrap().curve;
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

// ---------------------------------------------------------------------------------------
// Least squares and surfaces against geomdl 5.4.0 (tests/data/fit/geomdl_reference.json,
// written by tests/data/fit/make_geomdl_reference.py; the script's header says how to
// regenerate it): the same parameters and knots, then poles and residuals within 1e-9.

use nurbsx::nurbs::Grid;
use nurbsx::nurbs::fit::{SurfaceFitShape, approximate, fit_surface, grid_parameters};
use serde_json::Value;

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/fit/geomdl_reference.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn point(v: &Value) -> [f64; 3] {
    let f = floats(v);
    [f[0], f[1], f.get(2).copied().unwrap_or(0.0)]
}

fn method(v: &Value) -> ParamMethod {
    match v.as_str().unwrap() {
        "chord" => ParamMethod::ChordLength,
        "centripetal" => ParamMethod::Centripetal,
        other => panic!("{other}"),
    }
}

fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what}[{k}]: {x} vs {y}");
    }
}

#[test]
fn least_squares_curves_match_geomdl() {
    let r = reference();
    for (n, case) in r["curves"].as_array().unwrap().iter().enumerate() {
        let q: Vec<[f64; 3]> = case["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(point)
            .collect();
        let dim = case["points"][0].as_array().unwrap().len();
        let p = case["degree"].as_u64().unwrap() as usize;
        let poles = case["poles"].as_u64().unwrap() as usize;
        let m = method(&case["params"]);
        let fit = approximate(&q, p, poles, m, dim).unwrap();
        let what = format!("curve case {n}");
        close(&fit.parameters, &floats(&case["parameters"]), 1e-14, &what);
        close(fit.curve.knots(), &floats(&case["knots"]), 1e-14, &what);
        let want: Vec<[f64; 3]> = case["control_points"]
            .as_array()
            .unwrap()
            .iter()
            .map(point)
            .collect();
        assert_eq!(fit.curve.num_poles(), want.len(), "{what}");
        for (got, want) in fit.curve.control_points().iter().zip(&want) {
            close(got, want, 1e-9, &what);
        }
        // The ends are interpolated.
        assert_eq!(fit.curve.control_points()[0], q[0]);
        assert_eq!(fit.curve.control_points()[poles - 1], q[q.len() - 1]);
        let (max, rms) = (
            case["residual_max"].as_f64().unwrap(),
            case["residual_rms"].as_f64().unwrap(),
        );
        assert!(
            (fit.residual.max - max).abs() <= 1e-9,
            "{what}: {fit:?} vs {max}"
        );
        assert!(
            (fit.residual.rms - rms).abs() <= 1e-9,
            "{what}: {fit:?} vs {rms}"
        );
    }
}

#[test]
fn least_squares_minimises_the_squared_distances() {
    // Independent of geomdl: moving any interior pole in any direction raises the sum of
    // squared distances at the data parameters (the normal equations' optimum), and a
    // cubic through points that lie on a cubic is recovered exactly.
    let q: Vec<[f64; 3]> = (0..30)
        .map(|k| {
            let s = f64::from(k) / 29.0;
            [s, s * s * s - s, 0.3 * (7.0 * s).sin()]
        })
        .collect();
    let fit = approximate(&q, 3, 8, ParamMethod::ChordLength, 3).unwrap();
    let sum = |c: &nurbsx::nurbs::NurbsCurve| -> f64 {
        fit.parameters
            .iter()
            .zip(&q)
            .map(|(&t, p)| {
                let x = c.point_at(t).unwrap();
                (0..3).map(|d| (x[d] - p[d]).powi(2)).sum::<f64>()
            })
            .sum()
    };
    let best = sum(&fit.curve);
    assert!((best / q.len() as f64).sqrt() - fit.residual.rms < 1e-12);
    for i in 1..7 {
        for d in 0..3 {
            for h in [1e-4, -1e-4] {
                let mut poles = fit.curve.control_points().to_vec();
                poles[i][d] += h;
                let moved =
                    nurbsx::nurbs::NurbsCurve::new(3, fit.curve.knots().to_vec(), poles, None)
                        .unwrap();
                assert!(sum(&moved) > best, "pole {i} axis {d} step {h}");
            }
        }
    }
    // Points of a polynomial cubic at uniform parameters: residual ~0.
    let cubic: Vec<[f64; 3]> = (0..25)
        .map(|k| {
            let s = f64::from(k) / 24.0;
            [s, 2.0 * s * s - s * s * s, 1.0 - s]
        })
        .collect();
    let exact = approximate(&cubic, 3, 6, ParamMethod::Uniform, 3).unwrap();
    assert!(exact.residual.max < 1e-13, "{:?}", exact.residual);
    // Pole counts outside p + 1 <= n < points are refused.
    assert!(approximate(&q, 3, 3, ParamMethod::ChordLength, 3).is_err());
    assert!(approximate(&q, 3, 30, ParamMethod::ChordLength, 3).is_err());
}

fn grid_of(v: &Value) -> Grid<[f64; 3]> {
    let rows = v.as_array().unwrap();
    let nv = rows[0].as_array().unwrap().len();
    let data: Vec<[f64; 3]> = rows
        .iter()
        .flat_map(|r| r.as_array().unwrap().iter().map(point))
        .collect();
    Grid::from_u_major(rows.len(), nv, data).unwrap()
}

#[test]
fn surface_fits_match_geomdl() {
    let r = reference();
    for (n, case) in r["surfaces"].as_array().unwrap().iter().enumerate() {
        let what = format!("surface case {n}");
        let grid = grid_of(&case["grid"]);
        let deg = floats(&case["degree"]);
        let shape = SurfaceFitShape {
            degree_u: deg[0] as usize,
            degree_v: deg[1] as usize,
            poles: case["poles"].as_array().map(|p| {
                (
                    p[0].as_u64().unwrap() as usize,
                    p[1].as_u64().unwrap() as usize,
                )
            }),
        };
        let m = method(&case["params"]);
        let (tu, tv) = grid_parameters(&grid, m).unwrap();
        close(&tu, &floats(&case["parameters_u"]), 1e-14, &what);
        close(&tv, &floats(&case["parameters_v"]), 1e-14, &what);
        let fit = fit_surface(&grid, shape, m, 3).unwrap();
        close(
            fit.surface.knots_u(),
            &floats(&case["knots_u"]),
            1e-14,
            &what,
        );
        close(
            fit.surface.knots_v(),
            &floats(&case["knots_v"]),
            1e-14,
            &what,
        );
        let net = fit.surface.control_points();
        let size = floats(&case["poles_uv"]);
        assert_eq!(
            (net.nu(), net.nv()),
            (size[0] as usize, size[1] as usize),
            "{what}"
        );
        for (got, want) in net
            .as_slice()
            .iter()
            .zip(case["control_points"].as_array().unwrap())
        {
            close(got, &point(want), 1e-9, &what);
        }
        let (max, rms) = (
            case["residual_max"].as_f64().unwrap(),
            case["residual_rms"].as_f64().unwrap(),
        );
        assert!(
            (fit.residual.max - max).abs() <= 1e-9,
            "{what}: {:?} vs {max}",
            fit.residual
        );
        assert!(
            (fit.residual.rms - rms).abs() <= 1e-9,
            "{what}: {:?} vs {rms}",
            fit.residual
        );
    }
}

#[test]
fn surface_interpolation_passes_through_every_point() {
    // A 30 x 17 grid on a wavy, non-uniformly spaced sheet plus a sphere-like grid whose
    // first and last rows are single points (degenerate lines left out of the averaging of
    // A9.3); every degree pair 1..4: each data point at its parameters to 1e-12 of the
    // data size.
    let sheet = Grid::from_fn(30, 17, |i, j| {
        let (x, y) = ((i as f64 / 29.0).powf(1.3) * 10.0, (j as f64 / 16.0) * 6.0);
        [
            x,
            y + 0.3 * x.sin(),
            (0.7 * x).sin() * (1.1 * y).cos() * 2.0,
        ]
    });
    let ball = Grid::from_fn(13, 9, |i, j| {
        let th = std::f64::consts::PI * i as f64 / 12.0;
        let ph = 1.5 * std::f64::consts::PI * j as f64 / 8.0;
        [
            4.0 * th.sin() * ph.cos(),
            4.0 * th.sin() * ph.sin(),
            4.0 * th.cos(),
        ]
    });
    for (grid, size) in [(&sheet, 10.0), (&ball, 8.0)] {
        for m in [
            ParamMethod::Uniform,
            ParamMethod::ChordLength,
            ParamMethod::Centripetal,
        ] {
            let (tu, tv) = grid_parameters(grid, m).unwrap();
            for p in 1..=4 {
                for q in 1..=4 {
                    let shape = SurfaceFitShape {
                        degree_u: p,
                        degree_v: q,
                        poles: None,
                    };
                    let fit = fit_surface(grid, shape, m, 3).unwrap();
                    for (i, &u) in tu.iter().enumerate() {
                        for (j, &v) in tv.iter().enumerate() {
                            let got = fit.surface.point_at(u, v).unwrap();
                            let want = grid.get(i, j);
                            let err = (0..3).map(|k| (got[k] - want[k]).abs()).fold(0.0, f64::max);
                            assert!(err <= 1e-12 * size, "{m:?} ({p},{q}) at ({i},{j}): {err:e}");
                        }
                    }
                    assert!(fit.residual.max <= 1e-12 * size);
                }
            }
        }
    }
    // Too large a grid is refused before any work.
    let big = Grid::from_fn(600, 600, |i, j| [i as f64, j as f64, 0.0]);
    let shape = SurfaceFitShape {
        degree_u: 3,
        degree_v: 3,
        poles: None,
    };
    assert!(fit_surface(&big, shape, ParamMethod::Uniform, 3).is_err());
}
