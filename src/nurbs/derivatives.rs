//! Derivatives of any order of NURBS curves and surfaces.
//!
//! Curves: NURBS Book A3.2 CurveDerivsAlg1 on the homogeneous poles `(w x, w y, w z, w)`,
//! then A4.2 RatCurveDerivs (eq. 4.8):
//! `C^(k) = (A^(k) - sum_{i=1..k} Bin(k, i) w^(i) C^(k-i)) / w`.
//! Surfaces: A3.6 SurfaceDerivsAlg1 on the homogeneous net, then A4.4 RatSurfaceDerivs
//! (eq. 4.20). The unit normal ([`NurbsSurface::normal`]) handles degenerate points (sphere
//! poles, collapsed edges) with the limit of the normal from higher derivatives.

use super::basis::ders_basis_funs;
use super::knots::find_span;
use super::vector::{cross, norm, scale};
use super::{GeometryError, Hpoint, MAX_DEGREE, NurbsCurve, NurbsSurface, Point3};

/// The highest derivative order the APIs accept. Rational derivatives grow roughly like
/// `k!` and overflow `f64` not far above this, and the order is caller input (HTTP, CLI):
/// bounding it bounds the memory a request can ask for.
pub const MAX_DERIVATIVE_ORDER: usize = 128;

fn check_order(order: usize) -> Result<(), GeometryError> {
    if order > MAX_DERIVATIVE_ORDER {
        return Err(GeometryError::InvalidArgument(format!(
            "derivative order {order} exceeds the maximum {MAX_DERIVATIVE_ORDER}"
        )));
    }
    Ok(())
}

fn check_finite(values: impl IntoIterator<Item = Point3>, what: &str) -> Result<(), GeometryError> {
    for (k, d) in values.into_iter().enumerate() {
        if !d.iter().all(|c| c.is_finite()) {
            return Err(GeometryError::InvalidArgument(format!(
                "{what}: derivative #{k} overflows f64"
            )));
        }
    }
    Ok(())
}

/// Replaces `row` (holding `Bin(k-1, i)` for `i = 0..k-1`) by `Bin(k, i)`, `i = 0..=k`
/// (Pascal's rule, right to left so one row suffices). Only the first `row.len()` entries
/// are kept: callers need `i <= degree` only.
fn next_binomial_row(row: &mut [f64], k: usize) {
    let top = k.min(row.len() - 1);
    for i in (1..=top).rev() {
        row[i] += row[i - 1];
    }
}

/// A4.2 RatCurveDerivs: Euclidean derivatives `ck[0..=d]` from homogeneous derivatives
/// `aders` (`aders[k] = (A^(k), w^(k))`). `w^(i)` vanishes for `i > degree`, so only
/// `i <= degree` terms are summed. For a polynomial curve (`rational == false`) the weight
/// is identically 1 and the projection is skipped.
pub(crate) fn rat_curve_derivs(aders: &[Hpoint], degree: usize, rational: bool, ck: &mut [Point3]) {
    if !rational {
        for (c, a) in ck.iter_mut().zip(aders) {
            *c = [a[0], a[1], a[2]];
        }
        return;
    }
    let w0 = aders[0][3];
    let mut bin = vec![0.0; degree.min(aders.len()) + 1];
    bin[0] = 1.0;
    for k in 0..aders.len() {
        if k > 0 {
            next_binomial_row(&mut bin, k);
        }
        let mut v = [aders[k][0], aders[k][1], aders[k][2]];
        // i runs 1..=k; the index of C is k - i (the book's eq. 4.8; taking C^(k-1) instead
        // is a classic slip, caught by the finite-difference tests).
        for i in 1..=k.min(degree) {
            let f = bin[i] * aders[i][3];
            let c = ck[k - i];
            v[0] -= f * c[0];
            v[1] -= f * c[1];
            v[2] -= f * c[2];
        }
        ck[k] = [v[0] / w0, v[1] / w0, v[2] / w0];
    }
}

impl NurbsCurve {
    /// The point and its derivatives up to `order` at `u`: `[0]` is `C(u)`, `[k]` is
    /// `C^(k)(u)` (NURBS Book A3.2 + A4.2). Polynomial derivatives above the degree are 0;
    /// rational ones generally are not. At an interior knot of multiplicity `m` the
    /// derivatives of order `> p - m` are those of the span on the right (one-sided),
    /// except at the domain end where the last span is used.
    ///
    /// Errors: `u` outside the domain, `order > MAX_DERIVATIVE_ORDER`, or an overflowing
    /// result.
    pub fn derivatives(&self, u: f64, order: usize) -> Result<Vec<Point3>, GeometryError> {
        self.check_parameter(u)?;
        check_order(order)?;
        let aders = self.homogeneous_derivatives(u, order);
        let mut ck = vec![[0.0; 3]; order + 1];
        rat_curve_derivs(&aders, self.degree(), self.is_rational(), &mut ck);
        check_finite(ck.iter().copied(), "curve derivatives")?;
        Ok(ck)
    }

    /// A3.2 CurveDerivsAlg1 on homogeneous poles: `(A^(k), w^(k))`, `k = 0..=order`
    /// (zero above the degree). `u` must lie in the domain.
    pub(crate) fn homogeneous_derivatives(&self, u: f64, order: usize) -> Vec<Hpoint> {
        let p = self.degree();
        let du = order.min(p);
        let span = find_span(p, self.num_poles(), self.knots(), u);
        let (mut stack, mut heap) = ([0.0; BASIS_TABLE], Vec::new());
        let table = basis_table(&mut stack, &mut heap, (du + 1) * (p + 1));
        ders_basis_funs(span, u, p, du, self.knots(), table);
        let pts = self.control_points();
        let mut out = vec![[0.0; 4]; order + 1];
        for (k, row) in out.iter_mut().enumerate().take(du + 1) {
            for j in 0..=p {
                let i = span - p + j;
                // (N w) P, the order point_at uses, so that derivative 0 equals the point
                // bit for bit.
                let g = table[k * (p + 1) + j] * self.weight(i);
                let q = pts[i];
                row[0] += g * q[0];
                row[1] += g * q[1];
                row[2] += g * q[2];
                row[3] += g;
            }
        }
        out
    }
}

/// Entries of a basis-function derivative table (A2.3's `ders`) held on the stack: the
/// values and first derivatives of any degree.
const BASIS_TABLE: usize = (MAX_DEGREE + 1) * 2;

/// A table of `need` entries for A2.3: the front of `stack` when it fits, else `heap`
/// sized to it (higher derivatives).
fn basis_table<'a>(
    stack: &'a mut [f64; BASIS_TABLE],
    heap: &'a mut Vec<f64>,
    need: usize,
) -> &'a mut [f64] {
    if need <= BASIS_TABLE {
        &mut stack[..need]
    } else {
        heap.resize(need, 0.0);
        heap
    }
}

/// A4.4 RatSurfaceDerivs: Euclidean `skl[k][l]` (`k + l <= d`) from homogeneous
/// `aders[k][l] = (A^(k,l), w^(k,l))`. Terms with `w^(i,j)` above the degrees vanish.
/// `point` is `S(u, v)` itself (`skl[0][0]`), computed by the caller.
pub(crate) fn rat_surface_derivs(
    aders: &[Vec<Hpoint>],
    degrees: (usize, usize),
    rational: bool,
    point: Point3,
    skl: &mut [Vec<Point3>],
) {
    if !rational {
        for (row, arow) in skl.iter_mut().zip(aders) {
            for (s, a) in row.iter_mut().zip(arow) {
                *s = [a[0], a[1], a[2]];
            }
        }
        skl[0][0] = point;
        return;
    }
    let d = aders.len() - 1;
    let w = |k: usize, l: usize| -> f64 {
        if k <= degrees.0 && l <= degrees.1 {
            aders[k][l][3]
        } else {
            0.0
        }
    };
    let w00 = aders[0][0][3];
    // Full Pascal triangle up to d (d <= MAX_DERIVATIVE_ORDER, so at most 129^2 values).
    let mut bin = vec![vec![0.0; d + 1]; d + 1];
    for n in 0..=d {
        bin[n][0] = 1.0;
        for i in 1..=n {
            bin[n][i] = bin[n - 1][i - 1] + if i < n { bin[n - 1][i] } else { 0.0 };
        }
    }
    for k in 0..=d {
        for l in 0..=d - k {
            if k + l == 0 {
                skl[0][0] = point;
                continue;
            }
            let a = aders[k][l];
            let mut v = [a[0], a[1], a[2]];
            for j in 1..=l.min(degrees.1) {
                let f = bin[l][j] * w(0, j);
                let s = skl[k][l - j];
                for c in 0..3 {
                    v[c] -= f * s[c];
                }
            }
            for i in 1..=k.min(degrees.0) {
                let f = bin[k][i] * w(i, 0);
                let s = skl[k - i][l];
                let mut v2 = [0.0; 3];
                for j in 1..=l.min(degrees.1) {
                    let g = bin[l][j] * w(i, j);
                    let t = skl[k - i][l - j];
                    for c in 0..3 {
                        v2[c] += g * t[c];
                    }
                }
                for c in 0..3 {
                    v[c] -= f * s[c] + bin[k][i] * v2[c];
                }
            }
            skl[k][l] = [v[0] / w00, v[1] / w00, v[2] / w00];
        }
    }
}

impl NurbsSurface {
    /// All partial derivatives up to total order `order` at `(u, v)` (NURBS Book A3.6 +
    /// A4.4): `skl[k][l] = d^(k+l) S / du^k dv^l` for `k + l <= order`; `skl[k]` has
    /// `order - k + 1` entries. `skl[0][0]` is the point, `skl[1][0]` = S_u,
    /// `skl[0][1]` = S_v, `skl[1][1]` = S_uv.
    ///
    /// Errors: parameters outside the domain, `order > MAX_DERIVATIVE_ORDER`, overflow.
    pub fn derivatives(
        &self,
        u: f64,
        v: f64,
        order: usize,
    ) -> Result<Vec<Vec<Point3>>, GeometryError> {
        self.check_parameter(u, v)?;
        check_order(order)?;
        let aders = self.homogeneous_derivatives(u, v, order);
        // The point through point_at's exact arithmetic (v contracted first, division by the
        // weight sum even when polynomial), so [0][0] equals point_at bit for bit and the
        // higher derivatives are projected around that same point.
        let point = self.point_at_unchecked(u, v);
        let mut skl: Vec<Vec<Point3>> =
            (0..=order).map(|k| vec![[0.0; 3]; order - k + 1]).collect();
        rat_surface_derivs(
            &aders,
            (self.degree_u(), self.degree_v()),
            self.is_rational(),
            point,
            &mut skl,
        );
        check_finite(skl.iter().flatten().copied(), "surface derivatives")?;
        Ok(skl)
    }

    /// A3.6 SurfaceDerivsAlg1 on the homogeneous net: `aders[k][l]`, `k + l <= order`
    /// (zero where `k > p` or `l > q`). `(u, v)` must lie in the domain.
    pub(crate) fn homogeneous_derivatives(&self, u: f64, v: f64, order: usize) -> Vec<Vec<Hpoint>> {
        let (p, q) = (self.degree_u(), self.degree_v());
        let net = self.control_points();
        let (du, dv) = (order.min(p), order.min(q));
        let su = find_span(p, net.nu(), self.knots_u(), u);
        let sv = find_span(q, net.nv(), self.knots_v(), v);
        // The basis-function tables and the row of partial sums on the stack for the first
        // derivatives (the area and normal evaluations of every face, many points each),
        // on the heap above.
        let (mut nu_stack, mut nu_heap) = ([0.0; BASIS_TABLE], Vec::new());
        let (mut nv_stack, mut nv_heap) = ([0.0; BASIS_TABLE], Vec::new());
        let nu = basis_table(&mut nu_stack, &mut nu_heap, (du + 1) * (p + 1));
        let nv = basis_table(&mut nv_stack, &mut nv_heap, (dv + 1) * (q + 1));
        ders_basis_funs(su, u, p, du, self.knots_u(), nu);
        ders_basis_funs(sv, v, q, dv, self.knots_v(), nv);
        let mut out: Vec<Vec<Hpoint>> =
            (0..=order).map(|k| vec![[0.0; 4]; order - k + 1]).collect();
        let mut temp_stack = [[0.0; 4]; MAX_DEGREE + 1];
        let temp = &mut temp_stack[..=q];
        for k in 0..=du {
            for (s, t) in temp.iter_mut().enumerate() {
                *t = [0.0; 4];
                let j = sv - q + s;
                for r in 0..=p {
                    let i = su - p + r;
                    let f = nu[k * (p + 1) + r];
                    let w = self.weight(i, j);
                    let pt = net.get(i, j);
                    t[0] += f * (pt[0] * w);
                    t[1] += f * (pt[1] * w);
                    t[2] += f * (pt[2] * w);
                    t[3] += f * w;
                }
            }
            let dd = (order - k).min(dv);
            for l in 0..=dd {
                let mut acc = [0.0; 4];
                for (s, t) in temp.iter().enumerate() {
                    let g = nv[l * (q + 1) + s];
                    for c in 0..4 {
                        acc[c] += g * t[c];
                    }
                }
                out[k][l] = acc;
            }
        }
        out
    }

    /// The unit normal `S_u x S_v / |S_u x S_v|` at `(u, v)`.
    ///
    /// **Degenerate points** (a collapsed edge such as a sphere pole, where `S_u` or `S_v`
    /// vanishes, or a point where they are parallel): the normal is the limit of the unit
    /// normal as `(u, v)` is approached along the ray `t -> (u + s_u L_u t, v + s_v L_v t)`,
    /// `t -> 0+`, pointing into the domain (`s_u = -1` at the `u` end of the domain, else
    /// `+1`; likewise `s_v`; `L_u`, `L_v` the domain lengths). Along that ray
    /// `S_u x S_v = sum_m t^m c_m` with
    /// `c_m = sum_{i+j=m} D^i S_u x D^j S_v / (i! j!)` (`D` the derivative along the ray),
    /// and the normal is the first coefficient `c_m` that does not vanish, normalised
    /// (`m <= 6`). On a collapsed edge `v = v0` where `S_u = 0` this is `s_v (S_uv x S_v)`;
    /// where `S_v = 0` it is `s_u (S_u x S_uv)`. A coefficient vanishes when its length is
    /// below `(1e-10 size + 1e-14 magnitude) * size`, with `size` the diagonal of the box
    /// around the span's control points and `magnitude` their largest coordinate (the
    /// second term absorbs rounding far from the origin).
    ///
    /// Errors: parameters outside the domain, or no non-vanishing coefficient (no normal
    /// exists, e.g. a surface collapsed to a curve).
    pub fn normal(&self, u: f64, v: f64) -> Result<Point3, GeometryError> {
        self.check_parameter(u, v)?;
        let skl = self.derivatives(u, v, 1)?;
        let (su, sv) = (skl[1][0], skl[0][1]);
        let n = cross(su, sv);
        let ((u0, u1), (v0, v1)) = self.domain();
        let (lu, lv) = (u1 - u0, v1 - v0);
        let (tol, size) = self.local_size_tolerance(u, v);
        let thr = tol * size.max(tol);
        // Normalised parameters: derivatives per unit of the whole domain, so the tolerance
        // has units of length (squared for the cross product).
        if norm(n) * lu * lv > thr {
            return Ok(scale(n, 1.0 / norm(n)));
        }
        let su_dir = if u < u1 { 1.0 } else { -1.0 };
        let sv_dir = if v < v1 { 1.0 } else { -1.0 };
        let (a, b) = (su_dir * lu, sv_dir * lv);
        const M: usize = 6;
        let skl = self.derivatives(u, v, M + 1)?;
        // dsu[i] = D^i S_u, dsv[i] = D^i S_v along the ray (derivative w.r.t. t), in
        // normalised parameters: S_u scaled by L_u, S_v by L_v.
        let dir = |i: usize, du: usize, dv: usize| -> Point3 {
            // D^i of d^(du,dv) S = sum_{e=0..i} Bin(i,e) a^e b^(i-e) S_{du+e, dv+i-e}.
            let mut acc = [0.0; 3];
            let mut bin = 1.0;
            for e in 0..=i {
                let f = bin * a.powi(e as i32) * b.powi((i - e) as i32);
                let s = skl[du + e][dv + i - e];
                for c in 0..3 {
                    acc[c] += f * s[c];
                }
                bin = bin * (i - e) as f64 / (e + 1) as f64;
            }
            acc
        };
        let dsu: Vec<Point3> = (0..=M).map(|i| scale(dir(i, 1, 0), lu)).collect();
        let dsv: Vec<Point3> = (0..=M).map(|i| scale(dir(i, 0, 1), lv)).collect();
        let mut fact = [1.0; M + 1];
        for i in 1..=M {
            fact[i] = fact[i - 1] * i as f64;
        }
        for m in 0..=M {
            let mut c = [0.0; 3];
            for i in 0..=m {
                let x = cross(dsu[i], dsv[m - i]);
                let f = 1.0 / (fact[i] * fact[m - i]);
                for k in 0..3 {
                    c[k] += f * x[k];
                }
            }
            if norm(c) > thr {
                return Ok(scale(c, 1.0 / norm(c)));
            }
        }
        Err(GeometryError::InvalidArgument(format!(
            "no surface normal at (u, v) = ({u}, {v}): the surface is degenerate there"
        )))
    }

    /// `(1e-10 * size + 1e-14 * magnitude, size)` of the control points of the span at
    /// `(u, v)`: the length below which a (normalised) derivative vector counts as zero, and
    /// the local size (box diagonal).
    pub(crate) fn local_size_tolerance(&self, u: f64, v: f64) -> (f64, f64) {
        let (p, q) = (self.degree_u(), self.degree_v());
        let net = self.control_points();
        let su = find_span(p, net.nu(), self.knots_u(), u);
        let sv = find_span(q, net.nv(), self.knots_v(), v);
        let local = (su - p..=su).flat_map(|i| net.row(i)[sv - q..=sv].iter());
        let (lo, hi) = super::bounding_box(local.clone());
        let mag = local.flatten().fold(0.0_f64, |m, c| m.max(c.abs()));
        let size = super::distance(lo, hi);
        (1e-10 * size + 1e-14 * mag, size)
    }
}

impl NurbsCurve {
    /// The `k`-th derivative of a polynomial (non-rational) curve as a B-spline curve
    /// (NURBS Book A3.3 CurveDerivCpts; seed 000 eqs. 2-102 .. 2-104): degree `p - k`, knots
    /// `U` without its first and last `k` entries, control points
    /// `P^(k)_i = (p - k + 1) (P^(k-1)_{i+1} - P^(k-1)_i) / (u_{i+p+1} - u_{i+k})`
    /// (0 where the denominator is 0: that basis function vanishes). Works for clamped and
    /// unclamped knot vectors alike; the domain is unchanged.
    ///
    /// Errors ([`GeometryError::InvalidArgument`]): `k == 0` or `k >= p` (the result needs
    /// degree >= 1), an interior knot of multiplicity above `p - k` (the `k`-th
    /// derivative jumps there; the model allows interior multiplicity up to the degree), a rational curve (its derivative is rational of another degree, not of
    /// this form), or an overflowing control point.
    pub fn derivative_curve(&self, k: usize) -> Result<NurbsCurve, GeometryError> {
        let p = self.degree();
        if k == 0 || k >= p {
            return Err(GeometryError::InvalidArgument(format!(
                "derivative curve of order {k}: the order must be 1..={} for degree {p} \
                 (the result has degree p - k >= 1)",
                p.saturating_sub(1)
            )));
        }
        if self.is_rational() {
            return Err(GeometryError::InvalidArgument(
                "derivative curve: the derivative of a rational curve is not a B-spline of \
                 degree p - k (A3.3 applies to polynomial curves only)"
                    .into(),
            ));
        }
        let u = self.knots();
        let (a, b) = self.domain();
        if let Some((_, t, m)) =
            super::knots::runs(u).find(|&(_, t, m)| t > a && t < b && m > p - k)
        {
            return Err(GeometryError::InvalidArgument(format!(
                "derivative curve of order {k}: the interior knot {t} has multiplicity {m}, \
                 above p - k = {} (the k-th derivative jumps there, which a B-spline of \
                 degree p - k cannot hold)",
                p - k
            )));
        }
        let mut pk: Vec<Point3> = self.control_points().to_vec();
        for level in 1..=k {
            let f = (p - level + 1) as f64;
            pk = (0..pk.len() - 1)
                .map(|i| {
                    let den = u[i + p + 1] - u[i + level];
                    if den > 0.0 {
                        std::array::from_fn(|c| f * (pk[i + 1][c] - pk[i][c]) / den)
                    } else {
                        [0.0; 3]
                    }
                })
                .collect();
        }
        check_finite(pk.iter().copied(), "derivative control point")?;
        let knots = u[k..u.len() - k].to_vec();
        match NurbsCurve::with_dimension(p - k, knots, pk, None, self.dimension()) {
            // An unclamped vector whose domain end is a knot of multiplicity p - k + 1 or
            // more with knots outside it gives a derivative vector the model refuses (full
            // multiplicity away from the vector's ends); the clamped form (A5.1, exact, same
            // domain) has its ends at the vector's ends.
            Err(GeometryError::Multiplicity { .. })
                if !(self.is_clamped_start() && self.is_clamped_end()) =>
            {
                self.clamp()?.derivative_curve(k)
            }
            other => other,
        }
    }
}
