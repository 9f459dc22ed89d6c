//! Degree elevation of curves (NURBS Book A5.9 DegreeElevateCurve) and surfaces (A5.10
//! DegreeElevateSurface); seed 000 section 2-9 (Bezier elevation, eqs. 2-60 .. 2-65).
//!
//! The algorithms run in homogeneous space on "flat" pole arrays: pole `k` is
//! `data[k * dim .. (k + 1) * dim]`. A curve uses `dim = 4`; a surface elevated in u treats
//! each row of its homogeneous net (all v for one u index) as a single pole of
//! `dim = 4 * nv`, so one pass over the u knot vector elevates the whole net, which is what
//! A5.10 does.
//!
//! A5.9 assumes clamped ends. Unclamped knot vectors are handled by clamping first: the
//! domain ends `u_p` and `u_{n+1}` are inserted (A5.1) until they have multiplicity `p`,
//! and the poles whose basis functions vanish on the domain are dropped. This changes the
//! representation, not the curve on its domain, so the result has the same geometry on the
//! same domain; it is returned in clamped form.

use super::bernstein::binomial;
use super::double_double::{DoubleDouble as Dd, Scalar};
use super::knots::multiplicity;
use super::{GeometryError, Grid, Hpoint, MAX_DEGREE, NurbsCurve, NurbsSurface};

/// Flattens homogeneous points.
pub(super) fn flatten(h: &[Hpoint]) -> Vec<f64> {
    h.iter().flat_map(|q| q.iter().copied()).collect()
}

/// Back to homogeneous points (`data.len()` is a multiple of 4 by construction).
pub(super) fn unflatten(data: &[f64]) -> Vec<Hpoint> {
    data.chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// Inserts `u` `r` times into a flat pole array (NURBS Book A5.1 CurveKnotIns).
///
/// Preconditions (checked by the callers): `u` lies in the domain `[U_p, U_{n+1}]`, and
/// `multiplicity(u) + r <= p`.
pub(super) fn insert_flat(
    p: usize,
    knots: &[f64],
    poles: &[f64],
    dim: usize,
    u: f64,
    r: usize,
) -> (Vec<f64>, Vec<f64>) {
    if r == 0 {
        return (knots.to_vec(), poles.to_vec());
    }
    let np = poles.len() / dim;
    let n = np - 1;
    // k: last index with U_k <= u (u < U_m since u is in the domain and s + r <= p).
    let k = knots.partition_point(|&x| x <= u) - 1;
    let s = multiplicity(knots, u);
    let mut uq = Vec::with_capacity(knots.len() + r);
    uq.extend_from_slice(&knots[..=k]);
    uq.extend(std::iter::repeat_n(u, r));
    uq.extend_from_slice(&knots[k + 1..]);
    let mut q = vec![0.0; (np + r) * dim];
    q[..(k - p + 1) * dim].copy_from_slice(&poles[..(k - p + 1) * dim]);
    q[(k - s + r) * dim..].copy_from_slice(&poles[(k - s) * dim..(n + 1) * dim]);
    let mut rw: Vec<f64> = poles[(k - p) * dim..(k - s + 1) * dim].to_vec();
    let mut l = k - p;
    for j in 1..=r {
        l = k - p + j;
        for i in 0..=(p - j - s) {
            let alpha = (u - knots[l + i]) / (knots[i + k + 1] - knots[l + i]);
            for c in 0..dim {
                rw[i * dim + c] = alpha * rw[(i + 1) * dim + c] + (1.0 - alpha) * rw[i * dim + c];
            }
        }
        q[l * dim..(l + 1) * dim].copy_from_slice(&rw[..dim]);
        let last = k + r - j - s;
        q[last * dim..(last + 1) * dim]
            .copy_from_slice(&rw[(p - j - s) * dim..(p - j - s + 1) * dim]);
    }
    for i in (l + 1)..(k - s) {
        q[i * dim..(i + 1) * dim].copy_from_slice(&rw[(i - l) * dim..(i - l + 1) * dim]);
    }
    (uq, q)
}

/// Clamps a flat B-spline at both domain ends: inserts `U_p` and `U_{n+1}` up to
/// multiplicity `p` (A5.1), drops the poles whose basis functions vanish on the domain and
/// sets the `p + 1` end knots to the domain ends. The curve on its domain is unchanged (the
/// first and last knot of a clamped vector do not affect it: NURBS Book eq. 2.5 recurrence,
/// the term with `u_0` multiplies `N_{0,p-1}`, which is zero on the domain).
pub(super) fn clamp_flat(
    p: usize,
    knots: &[f64],
    poles: &[f64],
    dim: usize,
) -> (Vec<f64>, Vec<f64>) {
    let np = poles.len() / dim;
    let (a, b) = (knots[p], knots[np]);
    let s = multiplicity(knots, a);
    let (mut k, mut pw) = insert_flat(p, knots, poles, dim, a, p.saturating_sub(s));
    // r1: last index of the run of a; r1 >= p because k[p] == a.
    let r1 = k.partition_point(|&x| x <= a) - 1;
    let i0 = r1 - p;
    k.drain(..i0);
    pw.drain(..i0 * dim);
    for x in &mut k[..=p] {
        *x = a;
    }
    let s = multiplicity(&k, b);
    let (mut k, mut pw) = insert_flat(p, &k, &pw, dim, b, p.saturating_sub(s));
    // r0: first index of the run of b; poles 0..r0 have support reaching into the domain.
    let r0 = k.partition_point(|&x| x < b);
    k.truncate(r0 + p + 1);
    pw.truncate(r0 * dim);
    for x in &mut k[r0..] {
        *x = b;
    }
    (k, pw)
}

/// Input degrees from which [`elevate_flat`] runs in double-double: below it the rounding
/// of the `f64` path stays far under 1e-12 of the size, and the `f64` path is about 4.5
/// times faster (criterion `benches/degree.rs`).
const PRECISE_FROM_DEGREE: usize = 5;

/// [`elevate_flat_in`] in `f64` for low degrees, in double-double from
/// [`PRECISE_FROM_DEGREE`] with the poles rounded to `f64` once at the end.
pub(super) fn elevate_flat(
    p: usize,
    knots: &[f64],
    pw: &[f64],
    dim: usize,
    t: usize,
    stop: &dyn Fn() -> bool,
) -> Option<(Vec<f64>, Vec<f64>)> {
    if p < PRECISE_FROM_DEGREE {
        return elevate_flat_in::<f64>(p, knots, pw, dim, t, stop);
    }
    elevate_flat_precise(p, knots, pw, dim, t, stop)
        .map(|(knots, poles)| (knots, poles.into_iter().map(Dd::value).collect()))
}

/// [`elevate_flat_in`] in double-double, the poles kept so.
pub(super) fn elevate_flat_precise(
    p: usize,
    knots: &[f64],
    pw: &[f64],
    dim: usize,
    t: usize,
    stop: &dyn Fn() -> bool,
) -> Option<(Vec<f64>, Vec<Dd>)> {
    elevate_flat_in::<Dd>(p, knots, pw, dim, t, stop)
}

/// A5.9 DegreeElevateCurve on a clamped flat B-spline: degree `p` -> `p + t`, every knot's
/// multiplicity raised by `t`, in the arithmetic `T`. Returns `(knots, poles)`.
///
/// In `f64` the knot-removal divisions of A5.9 amplify the rounding of the Bezier round
/// trip: rational degree-8 and degree-9 curves moved by up to 4e-12 of their size (measured
/// against exact rational evaluation). In double-double (about 106 bits, see
/// `double_double`) the error left is the final rounding of the poles to `f64`.
///
/// Each pass extracts one Bezier segment by knot insertion, elevates it with the
/// coefficients `C(p, j) C(t, i - j) / C(p + t, i)` (eq. 5.36, seed 000 eq. 2-65 for repeated
/// elevation), and removes the inserted knots again from the previous segment's seam.
/// `stop` is polled once per segment (the work between two polls is one segment's
/// `O((p + t) p dim)`); `None` when it returned true.
// Index loops and counters mirror A5.9's pseudo-code line by line, which is how it is checked.
#[allow(clippy::needless_range_loop, clippy::explicit_counter_loop)]
fn elevate_flat_in<T: Scalar>(
    p: usize,
    knots: &[f64],
    pw: &[f64],
    dim: usize,
    t: usize,
    stop: &dyn Fn() -> bool,
) -> Option<(Vec<f64>, Vec<T>)> {
    let pw: Vec<T> = pw.iter().map(|&x| T::of(x)).collect();
    let one = T::of(1.0);
    let zero = T::of(0.0);
    let np = pw.len() / dim;
    let n = np - 1;
    let m = n + p + 1;
    let ph = p + t;
    let ph2 = ph / 2;
    let distinct = super::knots::runs(knots).count();
    let out_knots = m + 1 + t * distinct;
    let out_poles = out_knots - ph - 1;

    // Bezier degree elevation coefficients.
    let w = p + 1;
    let mut bezalfs = vec![zero; (ph + 1) * w];
    bezalfs[0] = one;
    bezalfs[ph * w + p] = one;
    for i in 1..=ph2 {
        let den = T::of(binomial(ph, i));
        for j in i.saturating_sub(t)..=p.min(i) {
            bezalfs[i * w + j] = T::of(binomial(p, j)) * T::of(binomial(t, i - j)) / den;
        }
    }
    for i in (ph2 + 1)..ph {
        for j in i.saturating_sub(t)..=p.min(i) {
            bezalfs[i * w + j] = bezalfs[(ph - i) * w + (p - j)];
        }
    }

    let mut uh = vec![0.0; out_knots];
    let mut qw = vec![zero; out_poles * dim];
    let mut bpts = vec![zero; (p + 1) * dim];
    let mut ebpts = vec![zero; (ph + 1) * dim];
    let mut next_bpts = vec![zero; (p + 1) * dim];
    let mut alfs = vec![zero; p + 1];

    // Signed indices: the algorithm's `r` starts at -1 and some comparisons go negative.
    let ix = |x: isize| -> usize { x as usize };
    let ph_i = ph as isize;
    let mut mh = ph;
    let mut kind: isize = ph_i + 1;
    let mut r: isize = -1;
    let mut a = p;
    let mut b = p + 1;
    let mut cind: isize = 1;
    let mut ua = knots[0];
    qw[..dim].copy_from_slice(&pw[..dim]);
    for x in &mut uh[..=ph] {
        *x = ua;
    }
    bpts.copy_from_slice(&pw[..(p + 1) * dim]);

    while b < m {
        if stop() {
            return None;
        }
        let i0 = b;
        while b < m && knots[b] == knots[b + 1] {
            b += 1;
        }
        let mul = b - i0 + 1;
        mh += mul + t;
        let ub = knots[b];
        let oldr = r;
        r = p as isize - mul as isize;
        let lbz: isize = if oldr > 0 { (oldr + 2) / 2 } else { 1 };
        let rbz: isize = if r > 0 { ph_i - (r + 1) / 2 } else { ph_i };
        if r > 0 {
            // Insert ub r times to isolate the Bezier segment [ua, ub].
            let numer = T::of(ub) - T::of(ua);
            for k in ((mul + 1)..=p).rev() {
                alfs[k - mul - 1] = numer / (T::of(knots[a + k]) - T::of(ua));
            }
            for j in 1..=ix(r) {
                let save = ix(r) - j;
                let s = mul + j;
                for k in (s..=p).rev() {
                    let al = alfs[k - s];
                    for c in 0..dim {
                        bpts[k * dim + c] =
                            al * bpts[k * dim + c] + (one - al) * bpts[(k - 1) * dim + c];
                    }
                }
                next_bpts[save * dim..(save + 1) * dim]
                    .copy_from_slice(&bpts[p * dim..(p + 1) * dim]);
            }
        }
        // Degree-elevate the Bezier segment (only points lbz..=ph are used below).
        for i in ix(lbz)..=ph {
            let e = &mut ebpts[i * dim..(i + 1) * dim];
            e.iter_mut().for_each(|x| *x = zero);
            for j in i.saturating_sub(t)..=p.min(i) {
                let f = bezalfs[i * w + j];
                for c in 0..dim {
                    e[c] = e[c] + f * bpts[j * dim + c];
                }
            }
        }
        if oldr > 1 {
            // Remove knot ua oldr times (it was inserted to split the previous segment).
            let mut first = kind - 2;
            let mut last = kind;
            let den = T::of(ub) - T::of(ua);
            let bet = (T::of(ub) - T::of(uh[ix(kind - 1)])) / den;
            for tr in 1..oldr {
                let mut i = first;
                let mut j = last;
                let mut kj = j - kind + 1;
                while j - i > tr {
                    if i < cind {
                        let alf = (T::of(ub) - T::of(uh[ix(i)])) / (T::of(ua) - T::of(uh[ix(i)]));
                        for c in 0..dim {
                            qw[ix(i) * dim + c] =
                                alf * qw[ix(i) * dim + c] + (one - alf) * qw[ix(i - 1) * dim + c];
                        }
                    }
                    if j >= lbz {
                        let g = if j - tr <= kind - ph_i + oldr {
                            (T::of(ub) - T::of(uh[ix(j - tr)])) / den
                        } else {
                            bet
                        };
                        for c in 0..dim {
                            ebpts[ix(kj) * dim + c] = g * ebpts[ix(kj) * dim + c]
                                + (one - g) * ebpts[ix(kj + 1) * dim + c];
                        }
                    }
                    i += 1;
                    j -= 1;
                    kj -= 1;
                }
                first -= 1;
                last += 1;
            }
        }
        if a != p {
            // Load the knot ua.
            for _ in 0..(ph_i - oldr) {
                uh[ix(kind)] = ua;
                kind += 1;
            }
        }
        for j in lbz..=rbz {
            qw[ix(cind) * dim..(ix(cind) + 1) * dim]
                .copy_from_slice(&ebpts[ix(j) * dim..(ix(j) + 1) * dim]);
            cind += 1;
        }
        if b < m {
            // Set up the next segment.
            for j in 0..ix(r.max(0)) {
                bpts[j * dim..(j + 1) * dim].copy_from_slice(&next_bpts[j * dim..(j + 1) * dim]);
            }
            for j in ix(r.max(0))..=p {
                let src = b - p + j;
                bpts[j * dim..(j + 1) * dim].copy_from_slice(&pw[src * dim..(src + 1) * dim]);
            }
            a = b;
            b += 1;
            ua = ub;
        } else {
            for i in 0..=ph {
                uh[ix(kind) + i] = ub;
            }
        }
    }
    debug_assert_eq!(mh - ph, out_poles);
    Some((uh, qw))
}

/// Checks `p + t <= MAX_DEGREE` and `t >= 1`.
fn check_elevation(p: usize, t: usize) -> Result<usize, GeometryError> {
    if t == 0 {
        return Err(GeometryError::InvalidArgument(
            "degree elevation: the amount t must be at least 1".into(),
        ));
    }
    match p.checked_add(t) {
        Some(ph) if ph <= MAX_DEGREE => Ok(ph),
        _ => Err(GeometryError::BadDegree {
            degree: p.saturating_add(t),
            max: MAX_DEGREE,
        }),
    }
}

/// Clamps (if needed) and elevates a flat B-spline by `t`, polling `stop` per segment
/// ([`GeometryError::Stopped`] when it fired).
fn clamp_and_elevate(
    p: usize,
    knots: &[f64],
    poles: &[f64],
    dim: usize,
    t: usize,
    stop: &dyn Fn() -> bool,
) -> Result<(Vec<f64>, Vec<f64>), GeometryError> {
    let (k, pw) = clamp_flat(p, knots, poles, dim);
    elevate_flat(p, &k, &pw, dim, t, stop).ok_or(GeometryError::Stopped)
}

impl NurbsCurve {
    /// Degree elevation by `t >= 1` (NURBS Book A5.9 DegreeElevateCurve; seed 000 eqs.
    /// 2-62 and 2-65 for the Bezier step), in homogeneous space so a rational curve stays
    /// rational and exact.
    ///
    /// The result has degree `p + t`, the same domain and the same geometry; every knot's
    /// multiplicity inside the domain grows by `t`. The result is clamped (end
    /// multiplicity `p + t + 1`): an unclamped input is first clamped at its domain ends by
    /// knot insertion, which leaves the curve on its domain unchanged.
    ///
    /// Errors: `t == 0` ([`GeometryError::InvalidArgument`]); `p + t > MAX_DEGREE`
    /// ([`GeometryError::BadDegree`]).
    pub fn elevate(&self, t: usize) -> Result<NurbsCurve, GeometryError> {
        self.elevate_polling(t, &|| false)
    }

    /// [`NurbsCurve::elevate`], polling `stop` once per Bezier segment of A5.9:
    /// [`GeometryError::Stopped`] once it returns true.
    pub fn elevate_polling(
        &self,
        t: usize,
        stop: &dyn Fn() -> bool,
    ) -> Result<NurbsCurve, GeometryError> {
        check_elevation(self.degree(), t)?;
        let hw = flatten(&self.homogeneous());
        let (k, q) = clamp_and_elevate(self.degree(), self.knots(), &hw, 4, t, stop)?;
        NurbsCurve::from_homogeneous(
            self.degree() + t,
            k,
            &unflatten(&q),
            self.is_rational(),
            self.dimension(),
        )
    }
}

impl NurbsSurface {
    /// Degree elevation by `t >= 1` in u (NURBS Book A5.10 DegreeElevateSurface, u
    /// direction): every row of the homogeneous net is elevated in one pass of A5.9 over
    /// the u knot vector. Same geometry and domain; the u knot vector comes back clamped.
    pub fn elevate_u(&self, t: usize) -> Result<NurbsSurface, GeometryError> {
        self.elevate_u_polling(t, &|| false)
    }

    /// [`NurbsSurface::elevate_u`], polling `stop` once per Bezier strip of the u pass
    /// (every row's segment at once): [`GeometryError::Stopped`] once it returns true.
    pub fn elevate_u_polling(
        &self,
        t: usize,
        stop: &dyn Fn() -> bool,
    ) -> Result<NurbsSurface, GeometryError> {
        check_elevation(self.degree_u(), t)?;
        let net = self.homogeneous();
        let nv = net.nv();
        let flat: Vec<f64> = flatten(net.as_slice());
        let (k, q) = clamp_and_elevate(self.degree_u(), self.knots_u(), &flat, 4 * nv, t, stop)?;
        let nu = q.len() / (4 * nv);
        let grid = Grid::from_u_major(nu, nv, unflatten(&q))
            .ok_or_else(|| GeometryError::InvalidArgument("elevated net shape".into()))?;
        NurbsSurface::from_homogeneous(
            self.degree_u() + t,
            self.degree_v(),
            k,
            self.knots_v().to_vec(),
            &grid,
            self.is_rational(),
            self.dimension(),
        )
    }

    /// Degree elevation by `t >= 1` in v (A5.10, v direction): the net is transposed so the
    /// columns become contiguous poles, elevated by A5.9, and transposed back.
    pub fn elevate_v(&self, t: usize) -> Result<NurbsSurface, GeometryError> {
        self.elevate_v_polling(t, &|| false)
    }

    /// [`NurbsSurface::elevate_v`], polling `stop` as [`NurbsSurface::elevate_u_polling`]
    /// does.
    pub fn elevate_v_polling(
        &self,
        t: usize,
        stop: &dyn Fn() -> bool,
    ) -> Result<NurbsSurface, GeometryError> {
        check_elevation(self.degree_v(), t)?;
        let net = self.homogeneous().transposed();
        let nu = net.nv();
        let flat: Vec<f64> = flatten(net.as_slice());
        let (k, q) = clamp_and_elevate(self.degree_v(), self.knots_v(), &flat, 4 * nu, t, stop)?;
        let nv = q.len() / (4 * nu);
        let grid = Grid::from_u_major(nv, nu, unflatten(&q))
            .ok_or_else(|| GeometryError::InvalidArgument("elevated net shape".into()))?
            .transposed();
        NurbsSurface::from_homogeneous(
            self.degree_u(),
            self.degree_v() + t,
            self.knots_u().to_vec(),
            k,
            &grid,
            self.is_rational(),
            self.dimension(),
        )
    }

    /// Degree elevation by `t >= 1` in both directions (A5.10 in u, then in v).
    pub fn elevate(&self, t: usize) -> Result<NurbsSurface, GeometryError> {
        self.elevate_u(t)?.elevate_v(t)
    }
}
