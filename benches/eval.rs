//! Evaluation throughput (points per second, one thread): a rational bicubic 20 x 20 surface
//! and a cubic curve with 20 poles, at random parameters and on sorted grids, for points
//! and points with first derivatives. Run with
//! `cargo bench --bench eval -- --warm-up-time 1 --measurement-time 3`; criterion prints
//! `thrpt` in elements (points) per second.
//!
//! **Clock:** by default the time measured is the benchmark thread's *CPU time* (Linux
//! `/proc/thread-self/schedstat`, nanoseconds on the CPU), so that figures stay meaningful on
//! a shared, overloaded build machine where wall time mostly measures waiting for a core. Set
//! `NURBSX_BENCH_WALL=1` to measure wall time instead (the right clock on an idle machine;
//! both agree there). Other processes still pollute caches, so a loaded machine reads low.
//! The kernel updates that counter at scheduler ticks, so every group samples *flat* (the
//! same, large, number of iterations per sample): criterion's default linear sampling starts
//! with one-iteration samples (about a millisecond for the fast rows), shorter than a tick,
//! which read as zero time.
//!
//! Reference (peers.md): Open CASCADE evaluates the rational surface point at 4.1 Mpts/s at
//! random parameters and 18.1 Mpts/s on a grid.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{BenchmarkId, Criterion, SamplingMode, Throughput, black_box};
use nurbsx::nurbs::batch::{CurveEvaluator, SurfaceEvaluator};
use nurbsx::nurbs::{Grid, NurbsCurve, NurbsSurface};

/// Points per iteration.
const N: usize = 100_000;

/// The calling thread's CPU time in nanoseconds (`/proc/thread-self/schedstat`, first
/// field), or `None` where unavailable.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Criterion measurement of thread CPU time, formatted like wall time (nanoseconds).
struct ThreadCpuTime {
    wall: WallTime,
}

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns().unwrap_or(0)
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns().unwrap_or(0).saturating_sub(start)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        self.wall.formatter()
    }
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn clamped_uniform(p: usize, n: usize) -> Vec<f64> {
    let spans = n - p;
    let mut k = vec![0.0; p + 1];
    k.extend((1..spans).map(|i| i as f64 / spans as f64));
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

fn surface(rng: &mut Lcg) -> NurbsSurface {
    let n = 20;
    let pts = Grid::from_fn(n, n, |i, j| {
        [
            i as f64,
            j as f64,
            (i as f64 * 0.7).sin() * (j as f64 * 0.4).cos() * 3.0,
        ]
    });
    let w = Grid::from_fn(n, n, |_, _| 0.5 + 1.5 * rng.next());
    NurbsSurface::new(
        3,
        3,
        clamped_uniform(3, n),
        clamped_uniform(3, n),
        pts,
        Some(w),
    )
    .unwrap()
}

fn curve(rng: &mut Lcg, rational: bool) -> NurbsCurve {
    let n = 20;
    let pts = (0..n)
        .map(|i| {
            [
                i as f64,
                (i as f64 * 0.9).sin() * 4.0,
                (i as f64 * 0.3).cos(),
            ]
        })
        .collect();
    let w = rational.then(|| (0..n).map(|_| 0.5 + 1.5 * rng.next()).collect());
    NurbsCurve::new(3, clamped_uniform(3, n), pts, w).unwrap()
}

fn bench_surface<M: Measurement>(c: &mut Criterion<M>) {
    let mut rng = Lcg(7);
    let s = surface(&mut rng);
    let ev = SurfaceEvaluator::new(&s);
    let uvs: Vec<[f64; 2]> = (0..N).map(|_| [rng.next(), rng.next()]).collect();
    let side = (N as f64).sqrt() as usize; // 316 x 316 = 99 856 points
    let grid: Vec<f64> = (0..side).map(|i| i as f64 / (side - 1) as f64).collect();
    let mut g = c.benchmark_group("surface_rational_bicubic_20x20");
    g.sampling_mode(SamplingMode::Flat);
    g.throughput(Throughput::Elements(N as u64));
    let mut out = Vec::with_capacity(N);
    g.bench_function("point_at/random", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &[u, v] in &uvs {
                acc += s.point_at(u, v).unwrap()[0];
            }
            black_box(acc)
        })
    });
    g.bench_function("point/random", |b| {
        b.iter(|| {
            ev.points(black_box(&uvs), &mut out).unwrap();
            black_box(out.len())
        })
    });
    let mut outd = Vec::with_capacity(N);
    g.bench_function("point+partials/random", |b| {
        b.iter(|| {
            ev.points_and_partials(black_box(&uvs), &mut outd).unwrap();
            black_box(outd.len())
        })
    });
    g.throughput(Throughput::Elements((side * side) as u64));
    g.bench_function(
        BenchmarkId::new("point/grid", format!("{side}x{side}")),
        |b| b.iter(|| black_box(ev.grid(black_box(&grid), black_box(&grid)).unwrap())),
    );
    g.bench_function(
        BenchmarkId::new("point+partials/grid", format!("{side}x{side}")),
        |b| {
            b.iter(|| {
                black_box(
                    ev.grid_with_partials(black_box(&grid), black_box(&grid))
                        .unwrap(),
                )
            })
        },
    );
    g.finish();
}

fn bench_curve<M: Measurement>(c: &mut Criterion<M>) {
    let mut rng = Lcg(11);
    for rational in [false, true] {
        let cv = curve(&mut rng, rational);
        let ev = CurveEvaluator::new(&cv);
        let us: Vec<f64> = (0..N).map(|_| rng.next()).collect();
        let sorted: Vec<f64> = (0..N).map(|i| i as f64 / (N - 1) as f64).collect();
        let name = if rational {
            "curve_rational_cubic_20"
        } else {
            "curve_cubic_20"
        };
        let mut g = c.benchmark_group(name);
        g.sampling_mode(SamplingMode::Flat);
        g.throughput(Throughput::Elements(N as u64));
        let mut out = Vec::with_capacity(N);
        let mut outd = Vec::with_capacity(N);
        g.bench_function("point_at/random", |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for &u in &us {
                    acc += cv.point_at(u).unwrap()[0];
                }
                black_box(acc)
            })
        });
        g.bench_function("point/random", |b| {
            b.iter(|| {
                ev.points(black_box(&us), &mut out).unwrap();
                black_box(out.len())
            })
        });
        g.bench_function("point/grid", |b| {
            b.iter(|| {
                ev.points_sorted(black_box(&sorted), &mut out).unwrap();
                black_box(out.len())
            })
        });
        g.bench_function("point/grid_bezier", |b| {
            b.iter(|| {
                ev.points_sorted_bezier(black_box(&sorted), &mut out)
                    .unwrap();
                black_box(out.len())
            })
        });
        g.bench_function("point+derivative/random", |b| {
            b.iter(|| {
                ev.points_and_derivatives(black_box(&us), &mut outd)
                    .unwrap();
                black_box(outd.len())
            })
        });
        g.bench_function("point+derivative/grid", |b| {
            b.iter(|| {
                ev.points_and_derivatives(black_box(&sorted), &mut outd)
                    .unwrap();
                black_box(outd.len())
            })
        });
        g.finish();
    }
}

fn main() {
    if std::env::var_os("NURBSX_BENCH_WALL").is_some() || thread_cpu_ns().is_none() {
        let mut c = Criterion::default().configure_from_args();
        bench_surface(&mut c);
        bench_curve(&mut c);
        c.final_summary();
    } else {
        let mut c = Criterion::default()
            .with_measurement(ThreadCpuTime { wall: WallTime })
            .configure_from_args();
        bench_surface(&mut c);
        bench_curve(&mut c);
        c.final_summary();
    }
}
