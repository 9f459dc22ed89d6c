//! # Areas, centroids and volumes of trimmed faces and solids
//!
//! A face's integrals run over its trimmed region `R` of the surface's parameter plane. By
//! Green's theorem (`∮ P du + Q dv = ∫∫ (Q_u - P_v) du dv`, with `P = 0` and
//! `Q = H(u, v) = ∫_{u_0}^{u} h(s, v) ds`) the region integral of any `h` is a boundary
//! integral: `∫∫_R h du dv = ∮_{∂R} H dv`, walked along the loops' pcurves. The integrands,
//! with `c = S_u × S_v` (ISO 10303-42 clause 4.4.1: the surface normal direction):
//! - `|c|`: the area element, so the area;
//! - `|c| S`: the area-weighted centroid;
//! - `S · c`: the flux of the position through the face, whose sum over a closed shell with
//!   outward faces is three times the enclosed volume (divergence theorem, `div x = 3`).
//!
//! `H` is integrated by 20-point Gauss-Legendre rules on each knot span of the surface in
//! u; the boundary integral by comparing 10- and 20-point rules on each knot span of each
//! pcurve and halving where they disagree. Loops are measured each with its own sign; the
//! outer loop counts positive and the holes negative whatever their orientation in the
//! file, so a face whose loops run the wrong way still measures right (the orientation is
//! checked elsewhere).

use super::{Face, FaceId, Model, ShellId, SolidId, loop_counter_clockwise};
use crate::nurbs::batch::SurfaceEvaluator;
use crate::nurbs::vector::{cross, dist, dot, norm};
use crate::nurbs::{NurbsCurve, Point3};

/// What could not be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeasureError {
    /// A coedge of a loop has no parameter-space curve, so the trimmed region is unknown.
    #[error("loop {index}, coedge {coedge}: no pcurve, the trimmed region is unknown")]
    NoPcurve {
        /// Loop index in the face.
        index: usize,
        /// Coedge index in the loop.
        coedge: usize,
    },
    /// A loop whose pcurves do not close in the parameter plane (a loop that winds around
    /// a closed surface without a seam edge, or pcurves far from each other).
    #[error(
        "loop {index}: its pcurves leave a gap of {gap:e} in the parameter plane after coedge {coedge}"
    )]
    OpenInParameters {
        /// Loop index in the face.
        index: usize,
        /// The coedge after which the gap is.
        coedge: usize,
        /// The gap, in parameter units.
        gap: f64,
    },
    /// Loops that wind around a closed surface without a seam edge in a way that bounds
    /// no region once (net turns other than -1, 0 or 1 against the face's orientation).
    #[error("the loops wind {turns} times around the closed surface")]
    Winding {
        /// Net turns (u turns minus v turns, against the face's orientation).
        turns: i64,
    },
    /// The surface or a pcurve could not be evaluated (non-finite values).
    #[error("the surface or a pcurve gives non-finite values")]
    NotFinite,
    /// A solid that does not exist.
    #[error("solid {0} does not exist")]
    NoSolid(usize),
    /// A shell that does not exist, or one of whose faces does not.
    #[error("shell {0} or one of its faces does not exist")]
    NoShell(usize),
    /// The adaptive boundary quadrature did not converge within the face's budget of
    /// integrand evaluations ([`FACE_EVALUATIONS`]): the face's measure is unknown.
    #[error("the measure did not converge within {evaluations} surface evaluations")]
    Unconverged {
        /// The evaluations spent before giving up.
        evaluations: u64,
    },
    /// The model's budget of integrand evaluations ([`MODEL_EVALUATIONS`]) was spent on the
    /// faces before this one: its measure is not computed.
    #[error("not measured: the model's budget of {evaluations} surface evaluations is spent")]
    ModelBudgetSpent {
        /// The model's budget.
        evaluations: u64,
    },
    /// A face of a shell or solid that could not be measured.
    #[error("face {face}: {source}")]
    InFace {
        /// The face's index in the model.
        face: usize,
        /// Why it could not be measured.
        source: Box<MeasureError>,
    },
}

/// The most surface evaluations (of `S_u × S_v`) one face's measure may spend. Each is
/// checked before it is spent, so a face whose integrand never converges ends as
/// [`MeasureError::Unconverged`] in bounded time whatever the input.
pub const FACE_EVALUATIONS: u64 = 1 << 22;

/// The most surface evaluations the measures of one model's faces ([`Model::totals`]) may
/// spend together, so that a file of many faces that never converge ends in bounded time
/// too (each such face alone is bounded by [`FACE_EVALUATIONS`]). About a minute of one
/// core; a measured part of 10 000 faces spends a few hundred evaluations per face.
pub const MODEL_EVALUATIONS: u64 = 1 << 28;

/// What is left of a face's evaluation budget of `size`.
struct Budget {
    left: std::cell::Cell<u64>,
    size: u64,
}

impl Budget {
    fn new(size: u64) -> Self {
        Budget {
            left: std::cell::Cell::new(size),
            size,
        }
    }

    /// Takes `n` evaluations, or fails without spending when fewer are left.
    fn take(&self, n: u64) -> Result<(), MeasureError> {
        let left = self.left.get();
        if n > left {
            return Err(MeasureError::Unconverged {
                evaluations: self.size - left,
            });
        }
        self.left.set(left - n);
        Ok(())
    }
}

/// A face's integrals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceMeasure {
    /// Area of the trimmed face.
    pub area: f64,
    /// Area-weighted centroid.
    pub centroid: Point3,
    /// `∫∫_R S · (S_u × S_v) du dv`: the flux of the position through the face along the
    /// surface normal (three times the volume of the cone from the origin to the face).
    pub flux: f64,
}

/// Components of the integrand: area, area x S (3), flux.
type Vec5 = [f64; 5];

fn add5(a: &mut Vec5, b: &Vec5, s: f64) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += s * y;
    }
}

/// The `n`-point Gauss-Legendre rule on [-1, 1]: nodes by Newton's iteration on `P_n` from
/// the Chebyshev-like guesses `cos(pi (i - 1/4) / (n + 1/2))`, weights `2 / ((1 - x^2) P_n'(x)^2)`.
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 1..=n {
        let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    rule
}

struct Rules {
    low: Vec<(f64, f64)>,
    high: Vec<(f64, f64)>,
}

fn rules() -> &'static Rules {
    static RULES: std::sync::OnceLock<Rules> = std::sync::OnceLock::new();
    RULES.get_or_init(|| Rules {
        low: gauss_legendre(10),
        high: gauss_legendre(20),
    })
}

/// The pieces `(x, y)` between consecutive breaks from `a` to `b`: `a`, the distinct knots
/// of the domain `[k_p, k_{n}]` strictly between `a` and `b` in walking order, and `b`, with
/// repeated values skipped (no empty piece). Nothing is allocated: the integrals ask for
/// these at every boundary point.
fn break_windows(knots: &[f64], p: usize, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let inner = knots.get(p..knots.len().saturating_sub(p)).unwrap_or(&[]);
    // The knots are non-decreasing: those inside (lo, hi) are one run.
    let start = inner.partition_point(|&k| k <= lo);
    let end = inner.partition_point(|&k| k < hi).max(start);
    let mid = inner.get(start..end).unwrap_or(&[]);
    let n = mid.len();
    let forward = a <= b;
    let mut prev = a;
    (1..=n + 1).filter_map(move |i| {
        let x = if i > n {
            b
        } else if forward {
            mid.get(i - 1).copied().unwrap_or(b)
        } else {
            mid.get(n - i).copied().unwrap_or(b)
        };
        if x == prev {
            return None;
        }
        let piece = (prev, x);
        prev = x;
        Some(piece)
    })
}

/// The integrand from `[S, S_u, S_v]`: `[|c|, |c| x, |c| y, |c| z, S · c]` with
/// `c = S_u × S_v`.
fn integrand([p, su, sv]: [Point3; 3]) -> Vec5 {
    let c = cross(su, sv);
    let g = norm(c);
    [g, g * p[0], g * p[1], g * p[2], dot(p, c)]
}

/// `H(u, v) = ∫_{u_0}^{u} h(s, v) ds`, 20-point rules on each knot span; the evaluations
/// are taken from `budget` before they are made. The nodes share `v`: the surface is
/// evaluated on them as a one-column grid (A3.6 + A4.4 with the net contracted in `v`
/// once for all of them, not once per node).
fn inner(s: &SurfaceEvaluator<'_>, u: f64, v: f64, budget: &Budget) -> Result<Vec5, MeasureError> {
    let surface = s.surface();
    let ((u0, u1), (v0, v1)) = surface.domain();
    let pieces = || break_windows(surface.knots_u(), surface.degree_u(), u0, u);
    let rule = &rules().high;
    let n = pieces().count() * rule.len();
    budget.take(n as u64)?;
    // The nodes, at the nearest parameters inside the domain; their weights are walked
    // again with the values.
    let mut nodes = Vec::with_capacity(n);
    for (x, y) in pieces() {
        let (mid, half) = (0.5 * (x + y), 0.5 * (y - x));
        nodes.extend(rule.iter().map(|&(t, _)| (mid + half * t).clamp(u0, u1)));
    }
    let weights = pieces().flat_map(|(x, y)| {
        let half = 0.5 * (y - x);
        rule.iter().map(move |&(_, wt)| wt * half)
    });
    let mut total = [0.0; 5];
    let Ok(grid) = s.grid_with_partials(&nodes, &[v.clamp(v0, v1)]) else {
        return Ok([f64::NAN; 5]);
    };
    for (d, w) in grid.as_slice().iter().zip(weights) {
        add5(&mut total, &integrand(*d), w);
    }
    Ok(total)
}

/// `∫ H(pc(t)) v'(t) dt` over `[a, b]` with one rule, and the same sum of absolute terms
/// (the scale its rounding errors are relative to).
fn boundary_rule(
    s: &SurfaceEvaluator<'_>,
    pc: &NurbsCurve,
    a: f64,
    b: f64,
    rule: &[(f64, f64)],
    budget: &Budget,
) -> Result<(Vec5, f64), MeasureError> {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut total = [0.0; 5];
    let mut mass = 0.0;
    for &(x, wt) in rule {
        let t = mid + half * x;
        let Ok(d) = pc.derivatives(t, 1) else {
            return Ok(([f64::NAN; 5], f64::NAN));
        };
        let (uv, dv) = (d[0], d[1][1]);
        let h = inner(s, uv[0], uv[1], budget)?;
        let w = wt * half * dv;
        mass += (w * h.iter().fold(0.0f64, |m, x| m.max(x.abs()))).abs();
        add5(&mut total, &h, w);
    }
    Ok((total, mass))
}

/// Largest number of pieces one pcurve span is cut into.
const MAX_PIECES: usize = 1 << 10;

/// `∫_a^b H(pc(t)) v'(t) dt`, adaptive on each knot span of the pcurve: a piece is kept when
/// its 10- and 20-point rules agree to 1e-12 of the size of its terms or to `floor` (the
/// face's scale: a pcurve along `u = u_0`, where `H` vanishes, carries only rounding noise
/// that no halving removes). A span along which `v` varies by at most `flat` is skipped:
/// its integral is at most `max |H|` times the total variation of `v`, which is at most
/// that of the span's control points (the variation diminishing property of B-splines,
/// NURBS Book section 2.3, also with positive weights), so such a span holds no more than
/// the rounding `floor` stands for (a pcurve along `v` = const fitted by projection has
/// hundreds of spans and only rounding in `v`).
fn boundary(
    s: &SurfaceEvaluator<'_>,
    pc: &NurbsCurve,
    (a, b): (f64, f64),
    (floor, flat): (f64, f64),
    budget: &Budget,
) -> Result<Vec5, MeasureError> {
    let mut total = [0.0; 5];
    for (x, y) in break_windows(pc.knots(), pc.degree(), a, b) {
        if variation_v(pc, 0.5 * (x + y)) <= flat {
            continue;
        }
        let mut stack = vec![(x, y)];
        let mut pieces = 0;
        while let Some((x, y)) = stack.pop() {
            let (high, mass) = boundary_rule(s, pc, x, y, &rules().high, budget)?;
            let (low, _) = boundary_rule(s, pc, x, y, &rules().low, budget)?;
            let diff = (0..5).map(|k| (high[k] - low[k]).abs()).fold(0.0, f64::max);
            pieces += 1;
            if diff <= (1e-12 * mass).max(floor)
                || pieces + stack.len() >= MAX_PIECES
                || diff.is_nan()
            {
                add5(&mut total, &high, 1.0);
            } else {
                let m = 0.5 * (x + y);
                stack.push((x, m));
                stack.push((m, y));
            }
        }
    }
    Ok(total)
}

/// The total variation of `v` over the control points of the knot span of `pc` holding
/// `t` (its `degree + 1` poles), which bounds the variation of `v(t)` along that span.
fn variation_v(pc: &NurbsCurve, t: f64) -> f64 {
    let (knots, p, poles) = (pc.knots(), pc.degree(), pc.control_points());
    // The span index k: knots[k] <= t < knots[k + 1], k in [p, n - 1].
    let n = poles.len();
    let k = knots
        .get(p + 1..n)
        .map_or(p, |inner| p + inner.partition_point(|&x| x <= t))
        .min(n.saturating_sub(1));
    poles
        .get(k.saturating_sub(p)..=k)
        .map_or(f64::INFINITY, |span| {
            span.windows(2).map(|w| (w[1][1] - w[0][1]).abs()).sum()
        })
}

/// `∫ H dv` along the straight segment from `p` to `q` (closing a small gap between
/// pcurves), 20-point rule.
fn segment(
    s: &SurfaceEvaluator<'_>,
    p: [f64; 2],
    q: [f64; 2],
    budget: &Budget,
) -> Result<Vec5, MeasureError> {
    let mut total = [0.0; 5];
    let dv = q[1] - p[1];
    if dv == 0.0 {
        return Ok(total);
    }
    for &(x, wt) in &rules().high {
        let f = 0.5 * (1.0 + x);
        let (u, v) = (p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1]));
        add5(&mut total, &inner(s, u, v, budget)?, 0.5 * wt * dv);
    }
    Ok(total)
}

/// `∫_{va}^{vb} H(u, v) dv` along `u` fixed, 20-point rules on each knot span in v.
fn column(
    s: &SurfaceEvaluator<'_>,
    u: f64,
    (va, vb): (f64, f64),
    budget: &Budget,
) -> Result<Vec5, MeasureError> {
    let mut total = [0.0; 5];
    let surface = s.surface();
    for (x, y) in break_windows(surface.knots_v(), surface.degree_v(), va, vb) {
        let (mid, half) = (0.5 * (x + y), 0.5 * (y - x));
        for &(x, wt) in &rules().high {
            add5(&mut total, &inner(s, u, mid + half * x, budget)?, wt * half);
        }
    }
    Ok(total)
}

impl Model {
    /// The area, centroid and flux of a face over its trimmed region (see the module).
    pub fn measure_face(&self, face: &Face) -> Result<FaceMeasure, MeasureError> {
        self.measure_face_within(face, FACE_EVALUATIONS)
    }

    /// [`Model::measure_face`] with at most `budget` evaluations of the integrand.
    fn measure_face_within(&self, face: &Face, budget: u64) -> Result<FaceMeasure, MeasureError> {
        self.measure_face_counted(face, &Budget::new(budget))
    }

    /// [`Model::measure_face`] within its own budget and what is left of a model's: `left`
    /// is (evaluations left, the model's budget), and goes down by what the face spends.
    /// [`MeasureError::ModelBudgetSpent`] when the model's budget runs out first.
    pub(crate) fn measure_face_sharing(
        &self,
        face: &Face,
        left: &mut (u64, u64),
    ) -> Result<FaceMeasure, MeasureError> {
        let spent = MeasureError::ModelBudgetSpent {
            evaluations: left.1,
        };
        if left.0 == 0 {
            return Err(spent);
        }
        let budget = Budget::new(FACE_EVALUATIONS.min(left.0));
        let m = self.measure_face_counted(face, &budget);
        left.0 -= budget.size - budget.left.get();
        match m {
            // The face stopped for want of what the model had left, not of its own budget.
            Err(MeasureError::Unconverged { .. }) if budget.size < FACE_EVALUATIONS => {
                left.0 = 0;
                Err(spent)
            }
            m => m,
        }
    }

    /// [`Model::measure_face`] spending from `budget` (what is left of it says how much the
    /// face took).
    fn measure_face_counted(
        &self,
        face: &Face,
        budget: &Budget,
    ) -> Result<FaceMeasure, MeasureError> {
        let s = &face.surface;
        let ((u0, u1), (v0, v1)) = s.domain();
        let eval = SurfaceEvaluator::new(s);
        let mut region = [0.0; 5];
        if face.loops.is_empty() {
            region = column(&eval, u1, (v0, v1), budget)?;
        } else {
            let closure = 1e-3 * ((u1 - u0).hypot(v1 - v0));
            // The size of the face's integrals: H across the whole domain times its v extent.
            let floor = 1e-14
                * (v1 - v0)
                * inner(&eval, u1, 0.5 * (v0 + v1), budget)?
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
            // A pcurve span along which v varies by no more than this holds at most about
            // `floor` (see `boundary`).
            let flat = 1e-14 * (v1 - v0);
            let on = |x: [f64; 2]| s.point_at_unchecked(x[0].clamp(u0, u1), x[1].clamp(v0, v1));
            let mut loops: Vec<(bool, Vec5)> = Vec::with_capacity(face.loops.len());
            // Times the loops wind around the surface in u minus in v (see below).
            let mut winding: i64 = 0;
            let mut wraps = false;
            for (index, l) in face.loops.iter().enumerate() {
                let mut total = [0.0; 5];
                let mut ends: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(l.coedges.len());
                let mut tolerances: Vec<f64> = Vec::with_capacity(l.coedges.len());
                for (k, c) in l.coedges.iter().enumerate() {
                    let pc = c
                        .pcurve
                        .as_ref()
                        .ok_or(MeasureError::NoPcurve { index, coedge: k })?;
                    let e = self.edges.get(c.edge.0).ok_or(MeasureError::NotFinite)?;
                    let (a, b) = if c.forward {
                        e.range
                    } else {
                        (e.range.1, e.range.0)
                    };
                    let (pa, pb) = pc.domain();
                    let (a, b) = (a.clamp(pa, pb), b.clamp(pa, pb));
                    let start = pc.point_at_unchecked(a);
                    let end = pc.point_at_unchecked(b);
                    ends.push(([start[0], start[1]], [end[0], end[1]]));
                    tolerances.push(e.tolerance);
                    // Walking the pcurve backwards negates the integral: boundary() takes
                    // its bounds in walking order.
                    let part = if a <= b {
                        boundary(&eval, pc, (a, b), (floor, flat), budget)?
                    } else {
                        let mut r = boundary(&eval, pc, (b, a), (floor, flat), budget)?;
                        r.iter_mut().for_each(|x| *x = -*x);
                        r
                    };
                    add5(&mut total, &part, 1.0);
                }
                let n = ends.len();
                for k in 0..n {
                    let (p, q) = (ends[k].1, ends[(k + 1) % n].0);
                    let gap = (q[0] - p[0]).hypot(q[1] - p[1]);
                    if gap <= closure {
                        add5(&mut total, &segment(&eval, p, q, budget)?, 1.0);
                        continue;
                    }
                    let same = dist(on(p), on(q)) <= tolerances[k];
                    let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
                    let wrap_u = (q[1] - p[1]).abs() <= closure
                        && ((q[0] - p[0]).abs() - (u1 - u0)).abs() <= closure;
                    let wrap_v = (q[0] - p[0]).abs() <= closure
                        && ((q[1] - p[1]).abs() - (v1 - v0)).abs() <= closure;
                    if gap.is_nan() || !same {
                        return Err(MeasureError::OpenInParameters {
                            index,
                            coedge: k,
                            gap,
                        });
                    }
                    if dist(on(p), on(mid)) <= tolerances[k] {
                        // Two coedges that meet at a pole (a sphere's or a cone's apex cut
                        // along its seam, the degenerate edge not written): the gap is the
                        // pole's parameter line, one 3-D point, and its segment closes the
                        // region as a degenerate edge's pcurve would.
                        add5(&mut total, &segment(&eval, p, q, budget)?, 1.0);
                    } else if wrap_u {
                        // The loop went once around a surface closed in u (no seam edge):
                        // closed through v = v0, where it encloses the part of the domain
                        // below it (H vanishes on u = u0, and dv = 0 along v0).
                        add5(&mut total, &column(&eval, p[0], (p[1], v0), budget)?, 1.0);
                        add5(&mut total, &column(&eval, q[0], (v0, q[1]), budget)?, 1.0);
                        winding += if p[0] > q[0] { 1 } else { -1 };
                        wraps = true;
                    } else if wrap_v {
                        // Around a surface closed in v: closed through u = u0, along which
                        // and along v0 and v1 nothing accrues; it encloses the part of the
                        // domain left of it.
                        winding -= if p[1] > q[1] { 1 } else { -1 };
                        wraps = true;
                    } else {
                        return Err(MeasureError::OpenInParameters {
                            index,
                            coedge: k,
                            gap,
                        });
                    }
                }
                loops.push((l.outer, total));
            }
            if wraps {
                // Loops around a closed surface without a seam edge (a band of a cylinder
                // between two circles, a cap of a sphere bounded by one parallel): each loop
                // closed as above bounds a region that contains a whole side of the domain,
                // so the loops' orientation says which side is the face's. With the face's
                // interior on the left of its loops in (u, v) when `same_sense` (ISO
                // 10303-42 face_bound, surface normal S_u x S_v), the face is the signed sum
                // of the loops plus the whole domain once for each net turn that runs with
                // the interior outside the closed regions (+u, or -v, turns).
                let o = if face.same_sense { 1.0 } else { -1.0 };
                let turns = if face.same_sense { winding } else { -winding };
                if !(-1..=1).contains(&turns) {
                    return Err(MeasureError::Winding { turns });
                }
                for (_, total) in &loops {
                    add5(&mut region, total, o);
                }
                if turns == 1 {
                    add5(&mut region, &column(&eval, u1, (v0, v1), budget)?, 1.0);
                }
                if region[0] < 0.0 {
                    region.iter_mut().for_each(|x| *x = -*x);
                }
            } else {
                // With no loop marked outer, the largest is.
                if !loops.iter().any(|l| l.0) {
                    if let Some(big) = loops
                        .iter_mut()
                        .max_by(|a, b| a.1[0].abs().total_cmp(&b.1[0].abs()))
                    {
                        big.0 = true;
                    }
                }
                for (outer, total) in &loops {
                    let sign = if total[0] < 0.0 { -1.0 } else { 1.0 };
                    add5(&mut region, total, if *outer { sign } else { -sign });
                }
            }
        }
        if region.iter().any(|x| !x.is_finite()) {
            return Err(MeasureError::NotFinite);
        }
        let area = region[0];
        let centroid = if area > 0.0 {
            [region[1] / area, region[2] / area, region[3] / area]
        } else {
            [f64::NAN; 3]
        };
        Ok(FaceMeasure {
            area,
            centroid,
            flux: region[4],
        })
    }

    /// The volume a solid encloses: a third of the flux of the position through its
    /// shells' faces, each along its outward normal (the surface normal when the face's
    /// `same_sense` agrees with its orientation in the shell). Voids count negative by their
    /// own orientation. Negative when the shells point inwards.
    pub fn solid_volume(&self, solid: SolidId) -> Result<f64, MeasureError> {
        self.volume_with(solid, |f| {
            let face = self.faces.get(f.0).ok_or(MeasureError::NoSolid(solid.0))?;
            self.measure_face(face)
        })
    }

    /// The volume one shell encloses, its faces signed by their orientation as in
    /// [`Model::solid_volume`]: positive when the shell faces away from what it encloses (a
    /// solid's outer shell), negative when it faces into it (a void's). The faces'
    /// measures are taken from `faces`, the model's in model order ([`Totals::faces`]: each
    /// face measured once, within the model's budget).
    pub fn shell_volume(
        &self,
        shell: ShellId,
        faces: &[Result<FaceMeasure, MeasureError>],
    ) -> Result<f64, MeasureError> {
        let flux = self.shell_flux_with(shell, |f| {
            faces
                .get(f.0)
                .cloned()
                .unwrap_or(Err(MeasureError::NoShell(shell.0)))
        })?;
        Ok(flux / 3.0)
    }

    /// [`Model::solid_volume`] with the faces measured by `measure`.
    fn volume_with(
        &self,
        solid: SolidId,
        measure: impl Fn(FaceId) -> Result<FaceMeasure, MeasureError>,
    ) -> Result<f64, MeasureError> {
        let s = self
            .solids
            .get(solid.0)
            .ok_or(MeasureError::NoSolid(solid.0))?;
        let mut flux = 0.0;
        for &shell in std::iter::once(&s.outer).chain(&s.voids) {
            flux += self.shell_flux_with(shell, &measure)?;
        }
        Ok(flux / 3.0)
    }

    /// The outward flux of the position through a shell's faces.
    fn shell_flux_with(
        &self,
        id: ShellId,
        measure: impl Fn(FaceId) -> Result<FaceMeasure, MeasureError>,
    ) -> Result<f64, MeasureError> {
        let shell = self.shells.get(id.0).ok_or(MeasureError::NoShell(id.0))?;
        let mut flux = 0.0;
        for &(f, orientation) in &shell.faces {
            let face = self.faces.get(f.0).ok_or(MeasureError::NoShell(id.0))?;
            let m = measure(f).map_err(|e| MeasureError::InFace {
                face: f.0,
                source: Box::new(e),
            })?;
            flux += if faces_outward(face, orientation) {
                m.flux
            } else {
                -m.flux
            };
        }
        Ok(flux)
    }
}

/// Whether a face used with `orientation` in a shell faces along its surface normal
/// `S_u × S_v`, so that its flux counts toward the enclosed volume as measured. The outer
/// bound runs counter-clockwise around the face normal (ISO 10303-42 face_outer_bound; IGES
/// 5.3 4.34), and sewing orients faces by their bounds: a face whose outer bound runs
/// clockwise in (u, v) against its sense (IGES 144s on surfaces whose NURBS (u, v) reverse
/// the file's) faces the other way round, and so does its flux.
///
/// A face with no outer bound (ISO 10303-42 face_bound only, as a band of a cylinder between
/// two full circles, pierced by holes) is bounded by loops that wind around its closed
/// surface, whose orientation in `(u, v)` says nothing: the loops that close in `(u, v)`
/// are its holes, which run clockwise around the face normal.
pub(crate) fn faces_outward(face: &Face, orientation: bool) -> bool {
    let ccw = |l: &super::Loop| loop_counter_clockwise(&face.surface, &l.coedges);
    let bound_agrees = match face.loops.iter().find(|l| l.outer) {
        Some(outer) => ccw(outer).is_none_or(|c| c == face.same_sense),
        None => face
            .loops
            .iter()
            .find_map(ccw)
            .is_none_or(|c| c != face.same_sense),
    };
    (face.same_sense == orientation) == bound_agrees
}

/// The measures of a whole model: what `info` shows and `--verify` compares.
#[derive(Debug, Clone, PartialEq)]
pub struct Totals {
    /// Each face's measure, in model order.
    pub faces: Vec<Result<FaceMeasure, MeasureError>>,
    /// Each solid's volume, in model order.
    pub volumes: Vec<Result<f64, MeasureError>>,
    /// Sum of the areas of the faces that could be measured.
    pub area: f64,
    /// Their area-weighted centroid (NaN without area).
    pub centroid: Point3,
    /// How many faces could not be measured.
    pub unmeasured: usize,
}

impl Model {
    /// Every face's area and centroid, every solid's volume, and the totals. Each face
    /// spends at most [`FACE_EVALUATIONS`], all of them together [`MODEL_EVALUATIONS`]: the
    /// faces after the budget is spent are not measured
    /// ([`MeasureError::ModelBudgetSpent`]; counted in [`Totals::unmeasured`]).
    pub fn totals(&self) -> Totals {
        self.totals_within(MODEL_EVALUATIONS)
    }

    /// [`Model::totals`] with a model budget of `evaluations`.
    fn totals_within(&self, evaluations: u64) -> Totals {
        let mut left = (evaluations, evaluations);
        let faces: Vec<Result<FaceMeasure, MeasureError>> = self
            .faces
            .iter()
            .map(|f| self.measure_face_sharing(f, &mut left))
            .collect();
        let (mut area, mut moment) = (0.0, [0.0; 3]);
        let mut unmeasured = 0;
        for m in &faces {
            match m {
                Ok(m) => {
                    area += m.area;
                    for (x, c) in moment.iter_mut().zip(m.centroid) {
                        *x += m.area * c;
                    }
                }
                Err(_) => unmeasured += 1,
            }
        }
        let centroid = if area > 0.0 {
            moment.map(|x| x / area)
        } else {
            [f64::NAN; 3]
        };
        let volumes = (0..self.solids.len())
            .map(|i| {
                self.volume_with(SolidId(i), |f| {
                    faces
                        .get(f.0)
                        .cloned()
                        .unwrap_or(Err(MeasureError::NoSolid(i)))
                })
            })
            .collect();
        Totals {
            faces,
            volumes,
            area,
            centroid,
            unmeasured,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{FACE_EVALUATIONS, MeasureError, break_windows, gauss_legendre};
    use crate::nurbs::grid::Grid;
    use crate::nurbs::{NurbsCurve, NurbsSurface};
    use crate::topology::{Coedge, Face, Loop, Model};

    /// The unit square [0, 1]^2 of the plane z = 0 as a face whose surface has `n` knot
    /// spans in u (degree 1) and whose four pcurves are straight lines of `n` spans each
    /// (degree 1, uniform), each edge a line in space: `n^2` times the work of the plain
    /// square, and the same area.
    fn square(n: usize) -> (Model, Face) {
        let knots = |n: usize| -> Vec<f64> {
            let mut k = vec![0.0];
            k.extend((0..=n).map(|i| i as f64 / n as f64));
            k.push(1.0);
            k
        };
        let surface = NurbsSurface::new(
            1,
            1,
            knots(n),
            vec![0.0, 0.0, 1.0, 1.0],
            Grid::from_fn(n + 1, 2, |i, j| [i as f64 / n as f64, j as f64, 0.0]),
            None,
        )
        .unwrap();
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mut m = Model::new();
        let vs: Vec<_> = corners
            .iter()
            .map(|c| m.add_vertex([c[0], c[1], 0.0], 1e-9).unwrap())
            .collect();
        let mut coedges = Vec::new();
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let line = |dim: usize| {
                let poles = (0..=n)
                    .map(|i| {
                        let t = i as f64 / n as f64;
                        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0]
                    })
                    .collect();
                NurbsCurve::with_dimension(1, knots(n), poles, None, dim).unwrap()
            };
            let edge = m
                .add_edge(line(3), (0.0, 1.0), vs[k], vs[(k + 1) % 4], 1e-9)
                .unwrap();
            coedges.push(Coedge {
                edge,
                forward: true,
                pcurve: Some(line(2)),
                pcurve_deviation: None,
            });
        }
        let face = Face {
            surface,
            loops: vec![Loop {
                coedges,
                outer: true,
            }],
            same_sense: true,
            vertex_loops: Vec::new(),
        };
        (m, face)
    }

    /// A face whose measure needs more evaluations than allowed ends `Unconverged`, having
    /// spent no more than allowed; the same face within the default budget measures exactly
    /// (area 1, centroid (1/2, 1/2, 0), flux 0: the plane z = 0 holds the origin), with the
    /// two pcurves along `v` = const skipped by their flat control points.
    #[test]
    fn a_face_beyond_its_budget_is_left_unmeasured() {
        let (m, face) = square(200);
        match m.measure_face_within(&face, 100_000) {
            Err(MeasureError::Unconverged { evaluations }) => assert!(evaluations <= 100_000),
            other => panic!("{other:?}"),
        }
        let (m, face) = square(8);
        let got = m.measure_face_within(&face, FACE_EVALUATIONS).unwrap();
        assert!((got.area - 1.0).abs() <= 1e-14, "{got:?}");
        assert!((got.centroid[0] - 0.5).abs() <= 1e-14, "{got:?}");
        assert!((got.centroid[1] - 0.5).abs() <= 1e-14, "{got:?}");
        assert!(got.flux.abs() <= 1e-14, "{got:?}");
    }

    /// The model's budget is shared by its faces in order: with room for two and a half
    /// faces, the first two are measured exactly, the third stops partway and the fourth
    /// is not started, both `ModelBudgetSpent`, and the totals count them as unmeasured.
    #[test]
    fn a_model_beyond_its_budget_leaves_its_last_faces_unmeasured() {
        let (mut m, face) = square(8);
        let one = super::Budget::new(FACE_EVALUATIONS);
        m.measure_face_counted(&face, &one).unwrap();
        let each = one.size - one.left.get();
        assert!(each > 0);
        m.faces = vec![face; 4];
        let totals = m.totals_within(2 * each + each / 2);
        for (k, f) in totals.faces.iter().enumerate() {
            match (k, f) {
                (0 | 1, Ok(got)) => assert!((got.area - 1.0).abs() <= 1e-14, "{got:?}"),
                (2 | 3, Err(MeasureError::ModelBudgetSpent { .. })) => {}
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(totals.unmeasured, 2);
        assert!((totals.area - 2.0).abs() <= 1e-14, "{totals:?}");
        // Within the default budget all four are measured.
        assert_eq!(m.totals().unmeasured, 0);
    }

    /// The pieces agree with the list written out: `a`, every domain knot strictly
    /// between (walking order), `b`, consecutive repeats dropped, paired up.
    #[test]
    fn break_windows_walk_the_knots_between_the_ends() {
        let reference = |knots: &[f64], p: usize, a: f64, b: f64| -> Vec<(f64, f64)> {
            let (lo, hi) = (a.min(b), a.max(b));
            let mut inner: Vec<f64> = knots[p..knots.len() - p]
                .iter()
                .copied()
                .filter(|&k| k > lo && k < hi)
                .collect();
            if a > b {
                inner.reverse();
            }
            let mut all = vec![a];
            all.extend(inner);
            all.push(b);
            all.dedup();
            all.windows(2).map(|w| (w[0], w[1])).collect()
        };
        let knots = [0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 0.75, 1.0, 1.0, 1.0];
        let ends = [0.0, 0.1, 0.25, 0.5, 0.6, 0.75, 1.0, -0.5, 1.5];
        for &a in &ends {
            for &b in &ends {
                let got: Vec<(f64, f64)> = break_windows(&knots, 2, a, b).collect();
                assert_eq!(got, reference(&knots, 2, a, b), "{a} -> {b}");
            }
        }
        assert_eq!(break_windows(&knots, 2, 0.3, 0.3).count(), 0);
        let nan: Vec<(f64, f64)> = break_windows(&knots, 2, 0.0, f64::NAN).collect();
        assert!(nan.len() == 1 && nan[0].0 == 0.0 && nan[0].1.is_nan());
    }

    /// The rules integrate x^k exactly up to degree 2n - 1 (checked against 2 / (k + 1)).
    #[test]
    fn gauss_legendre_is_exact_on_polynomials() {
        for n in [10, 20] {
            let rule = gauss_legendre(n);
            assert_eq!(rule.len(), n);
            for k in 0..2 * n {
                let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
                let want = if k % 2 == 0 {
                    2.0 / (k as f64 + 1.0)
                } else {
                    0.0
                };
                assert!((got - want).abs() <= 1e-14, "n {n} k {k}: {got} vs {want}");
            }
        }
    }
}
