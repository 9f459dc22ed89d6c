//! Bezier decomposition (NURBS Book A5.6 DecomposeCurve; surfaces as A5.7
//! DecomposeSurface, one direction after the other).
//!
//! Unclamped input is clamped first (exact, [`clamp`](super::clamp)), so A5.6's clamped
//! precondition always holds. Each segment covers one non-empty knot span `[a, b]` of the
//! domain and is returned as a clamped B-spline with knots `[a; p+1] ++ [b; p+1]`, so it
//! evaluates like the original at the same parameters.

use super::clamp::clamp_bundle;
use super::insert::{Bundle, Dir, lerp};
use super::{GeometryError, Grid, Hpoint, NurbsCurve, NurbsSurface};

/// One Bezier segment of a bundle: its span and `p + 1` poles per row.
pub(super) struct Segment {
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) rows: Vec<Vec<Hpoint>>,
}

impl Segment {
    fn into_bundle(self, degree: usize) -> Bundle {
        let mut knots = vec![self.a; degree + 1];
        knots.extend(std::iter::repeat_n(self.b, degree + 1));
        Bundle {
            degree,
            knots,
            rows: self.rows,
        }
    }
}

/// A5.6 on every row of the clamped bundle, alphas shared by all rows.
pub(super) fn decompose_bundle(b: &Bundle) -> Vec<Segment> {
    let c = clamp_bundle(b);
    let p = c.degree;
    let u = &c.knots;
    let m = u.len() - 1;
    let nrows = c.rows.len();
    let mut segments = Vec::new();
    let mut cur: Vec<Vec<Hpoint>> = c.rows.iter().map(|r| r[..=p].to_vec()).collect();
    let mut a = p;
    let mut bi = p + 1;
    while bi < m {
        let i = bi;
        while bi < m && u[bi + 1] == u[bi] {
            bi += 1;
        }
        let mult = bi - i + 1;
        let mut next = vec![vec![[0.0; 4]; p + 1]; nrows];
        if mult < p {
            let numer = u[bi] - u[a];
            // alphas[j - mult - 1] for j = p down to mult + 1.
            let alphas: Vec<f64> = (mult + 1..=p).map(|j| numer / (u[a + j] - u[a])).collect();
            let r = p - mult;
            for j in 1..=r {
                let save = r - j;
                let s = mult + j;
                for (row, nx) in cur.iter_mut().zip(next.iter_mut()) {
                    for k in (s..=p).rev() {
                        row[k] = lerp(row[k - 1], row[k], alphas[k - s]);
                    }
                    nx[save] = row[p];
                }
            }
        }
        let done = bi >= m;
        if !done {
            for (nx, pw) in next.iter_mut().zip(&c.rows) {
                for ii in p - mult.min(p)..=p {
                    nx[ii] = pw[bi - p + ii];
                }
            }
        }
        segments.push(Segment {
            a: u[a],
            b: u[bi],
            rows: std::mem::replace(&mut cur, next),
        });
        if done {
            break;
        }
        a = bi;
        bi += 1;
    }
    segments
}

impl NurbsCurve {
    /// The Bezier segments of the curve, one per non-empty knot span of the domain, in order
    /// (NURBS Book A5.6 DecomposeCurve in homogeneous space; unclamped input is clamped
    /// first). Segment `k` has knots `[a; p+1] ++ [b; p+1]` for its span `[a, b]` and equals
    /// the curve there. Errors only if a computed value overflows.
    pub fn bezier_segments(&self) -> Result<Vec<NurbsCurve>, GeometryError> {
        decompose_bundle(&self.to_bundle())
            .into_iter()
            .map(|s| self.with_bundle(s.into_bundle(self.degree())))
            .collect()
    }
}

impl NurbsSurface {
    /// The Bezier patches of the surface (A5.7 DecomposeSurface, done as A5.6 along u, then
    /// along v on each strip), as a grid indexed `(i, j)` = (u span, v span). Patch `(i, j)`
    /// has knots `[a_i; p+1] ++ [b_i; p+1]` in u and likewise in v, and equals the surface on
    /// its knot rectangle.
    pub fn bezier_patches(&self) -> Result<Grid<NurbsSurface>, GeometryError> {
        let strips = decompose_bundle(&self.to_bundle(Dir::U));
        let nsu = strips.len();
        let mut patches = Vec::new();
        let mut nsv = 0;
        for strip in strips {
            let s = self.with_bundle(Dir::U, strip.into_bundle(self.degree_u()))?;
            let pieces = decompose_bundle(&s.to_bundle(Dir::V));
            nsv = pieces.len();
            for piece in pieces {
                patches.push(s.with_bundle(Dir::V, piece.into_bundle(self.degree_v()))?);
            }
        }
        Grid::from_u_major(nsu, nsv, patches)
            .ok_or_else(|| GeometryError::InvalidArgument("ragged Bezier patch grid".into()))
    }
}
