//! Typed records for the entities nurbsx maps: 124, 126 and 128. All other entities stay
//! raw ([`Parameters`] gives typed access to any parameter).

pub mod layout;

use super::Parameters;
use super::error::{ErrorKind, ParseError};
use super::writer::Param;
pub use layout::{CurveLayout, SurfaceLayout};

/// Entity 126, Rational B-Spline Curve (IGES 5.3 section 4.23; spec.md b.1).
///
/// | index | name | meaning |
/// |---|---|---|
/// | 1 | K | upper index of the sum |
/// | 2 | M | degree |
/// | 3-6 | PROP1-4 | planar, closed, polynomial, periodic (0/1) |
/// | 7.. | T(-M)..T(N+M) | `K+M+2` knots |
/// | .. | W(0)..W(K) | weights |
/// | .. | X0,Y0,Z0..ZK | control points |
/// | .. | V(0), V(1) | parameter range (optional here) |
/// | .. | XNORM,YNORM,ZNORM | unit normal if planar (optional here) |
///
/// The PROP flags are kept as written (0/1 per the spec; other values are kept for the
/// exchange layer to report).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve126 {
    /// Degree `M`.
    pub degree: usize,
    /// PROP1: 1 = planar.
    pub planar: i64,
    /// PROP2: 1 = closed.
    pub closed: i64,
    /// PROP3: 1 = polynomial, 0 = rational.
    pub polynomial: i64,
    /// PROP4: 1 = periodic.
    pub periodic: i64,
    /// `K + M + 2` knots `T(-M)..T(K+1)`.
    pub knots: Vec<f64>,
    /// `K + 1` weights.
    pub weights: Vec<f64>,
    /// `K + 1` control points (Euclidean).
    pub points: Vec<[f64; 3]>,
    /// `V(0)`, absent when the record ends before it.
    pub v0: Option<f64>,
    /// `V(1)`.
    pub v1: Option<f64>,
    /// The unit normal, absent when the record ends before it.
    pub normal: Option<[f64; 3]>,
    /// Parameters after the full record (associativity/property pointer groups, or extra
    /// values some writers add).
    pub extra: usize,
}

/// Entity 128, Rational B-Spline Surface (IGES 5.3 section 4.24; spec.md b.2).
///
/// Weights and control points are kept in the file's order, the **first index fastest**:
/// `W(0,0), W(1,0), .., W(K1,0), W(0,1), ..`; [`Surface128::index`] maps `(i, j)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface128 {
    /// `M1`, `M2`.
    pub degree: [usize; 2],
    /// `K1 + 1`, `K2 + 1`: control points along u and v.
    pub poles: [usize; 2],
    /// PROP1, PROP2: closed in u, in v.
    pub closed: [i64; 2],
    /// PROP3: 1 = polynomial.
    pub polynomial: i64,
    /// PROP4, PROP5: periodic in u, in v.
    pub periodic: [i64; 2],
    /// u knots `S(-M1)..S(N1+M1)`.
    pub knots_u: Vec<f64>,
    /// v knots `T(-M2)..T(N2+M2)`.
    pub knots_v: Vec<f64>,
    /// Weights, first index fastest.
    pub weights: Vec<f64>,
    /// Control points, first index fastest.
    pub points: Vec<[f64; 3]>,
    /// `U(0), U(1), V(0), V(1)` when all four are present.
    pub range: Option<[f64; 4]>,
    /// Parameters after the full record.
    pub extra: usize,
}

/// Entity 124, Transformation Matrix (IGES 5.3 section 4.21): `x' = R x + T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform124 {
    /// Rows `[R11 R12 R13 T1], [R21 R22 R23 T2], [R31 R32 R33 T3]`.
    pub rows: [[f64; 4]; 3],
    /// Form number: 0/1 transforms, 10-12 coordinate systems.
    pub form: i64,
}

fn check_type(p: &Parameters<'_>, expected: i64) -> Result<(), ParseError> {
    if p.entity_type != expected {
        return Err(p.error_at(
            0,
            ErrorKind::WrongEntity {
                found: p.entity_type,
                expected,
            },
        ));
    }
    Ok(())
}

/// Checks that parameter `required` exists before anything is allocated.
fn check_present(p: &Parameters<'_>, required: usize, what: &str) -> Result<(), ParseError> {
    if p.len() <= required {
        return Err(p.error_at(
            p.len(),
            ErrorKind::Truncated {
                what: what.to_owned(),
                needed: required,
                present: p.len().saturating_sub(1),
            },
        ));
    }
    Ok(())
}

fn points_into(
    p: &Parameters<'_>,
    from: usize,
    count: usize,
    out: &mut Vec<[f64; 3]>,
) -> Result<(), ParseError> {
    for k in 0..count {
        let i = from + 3 * k;
        out.push([p.real(i, "X")?, p.real(i + 1, "Y")?, p.real(i + 2, "Z")?]);
    }
    Ok(())
}

impl Curve126 {
    /// Decodes a tokenized 126 record.
    pub fn from_params(p: &Parameters<'_>) -> Result<Self, ParseError> {
        check_type(p, 126)?;
        let k = p.int(1, "K")?;
        let m = p.int(2, "M")?;
        let l = CurveLayout::new(k, m).map_err(|e| p.error_at(1, ErrorKind::OutOfRange(e)))?;
        check_present(p, l.required, &format!("126 with K = {k}, M = {m}"))?;
        let prop = |i, name| p.int_or(i, name, 0);
        let mut knots = Vec::with_capacity(l.knot_count);
        p.reals_into(l.knots, l.knot_count, "knot", &mut knots)?;
        let mut weights = Vec::with_capacity(l.poles);
        p.reals_into(l.weights, l.poles, "weight", &mut weights)?;
        let mut points = Vec::with_capacity(l.poles);
        points_into(p, l.points, l.poles, &mut points)?;
        let v0 = p.opt_real(l.v0, "V(0)")?;
        let v1 = p.opt_real(l.v0 + 1, "V(1)")?;
        let normal = if p.len() > l.normal + 2 {
            match (
                p.opt_real(l.normal, "XNORM")?,
                p.opt_real(l.normal + 1, "YNORM")?,
                p.opt_real(l.normal + 2, "ZNORM")?,
            ) {
                (None, None, None) => None,
                (x, y, z) => Some([x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0)]),
            }
        } else {
            None
        };
        Ok(Curve126 {
            degree: l.m,
            planar: prop(3, "PROP1")?,
            closed: prop(4, "PROP2")?,
            polynomial: prop(5, "PROP3")?,
            periodic: prop(6, "PROP4")?,
            knots,
            weights,
            points,
            v0,
            v1,
            normal,
            extra: p.len().saturating_sub(l.full + 1),
        })
    }

    /// The parameters to write (entity type first), with `V(0), V(1)` and the normal
    /// written when present (a missing range or normal ends the record early).
    pub fn to_params(&self) -> Vec<Param> {
        let k = self.points.len().saturating_sub(1);
        let mut v = Vec::with_capacity(12 + self.knots.len() + 4 * self.points.len());
        v.push(Param::Int(126));
        v.push(Param::Int(to_i64(k)));
        v.push(Param::Int(to_i64(self.degree)));
        for f in [self.planar, self.closed, self.polynomial, self.periodic] {
            v.push(Param::Int(f));
        }
        v.extend(self.knots.iter().map(|&x| Param::Real(x)));
        v.extend(self.weights.iter().map(|&x| Param::Real(x)));
        for q in &self.points {
            v.extend(q.iter().map(|&x| Param::Real(x)));
        }
        if let (Some(a), Some(b)) = (self.v0, self.v1) {
            v.push(Param::Real(a));
            v.push(Param::Real(b));
            if let Some(n) = self.normal {
                v.extend(n.iter().map(|&x| Param::Real(x)));
            }
        }
        v
    }
}

impl Surface128 {
    /// Position of pole `(i, j)` (i along u) in [`Surface128::points`] / `weights`.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.poles[0] + i
    }

    /// Decodes a tokenized 128 record.
    pub fn from_params(p: &Parameters<'_>) -> Result<Self, ParseError> {
        check_type(p, 128)?;
        let k1 = p.int(1, "K1")?;
        let k2 = p.int(2, "K2")?;
        let m1 = p.int(3, "M1")?;
        let m2 = p.int(4, "M2")?;
        let l = SurfaceLayout::new(k1, k2, m1, m2)
            .map_err(|e| p.error_at(1, ErrorKind::OutOfRange(e)))?;
        check_present(
            p,
            l.required,
            &format!("128 with K1 = {k1}, K2 = {k2}, M1 = {m1}, M2 = {m2}"),
        )?;
        let prop = |i, name| p.int_or(i, name, 0);
        let mut knots_u = Vec::with_capacity(l.knot_count[0]);
        p.reals_into(l.knots_u, l.knot_count[0], "S knot", &mut knots_u)?;
        let mut knots_v = Vec::with_capacity(l.knot_count[1]);
        p.reals_into(l.knots_v, l.knot_count[1], "T knot", &mut knots_v)?;
        let n = l.pole_count();
        let mut weights = Vec::with_capacity(n);
        p.reals_into(l.weights, n, "weight", &mut weights)?;
        let mut points = Vec::with_capacity(n);
        points_into(p, l.points, n, &mut points)?;
        let r = l.range;
        let range = match (
            p.opt_real(r, "U(0)")?,
            p.opt_real(r + 1, "U(1)")?,
            p.opt_real(r + 2, "V(0)")?,
            p.opt_real(r + 3, "V(1)")?,
        ) {
            (Some(a), Some(b), Some(c), Some(d)) => Some([a, b, c, d]),
            _ => None,
        };
        Ok(Surface128 {
            degree: l.m,
            poles: l.poles,
            closed: [prop(5, "PROP1")?, prop(6, "PROP2")?],
            polynomial: prop(7, "PROP3")?,
            periodic: [prop(8, "PROP4")?, prop(9, "PROP5")?],
            knots_u,
            knots_v,
            weights,
            points,
            range,
            extra: p.len().saturating_sub(l.full + 1),
        })
    }

    /// The parameters to write (entity type first); the range is written when present.
    pub fn to_params(&self) -> Vec<Param> {
        let mut v = Vec::with_capacity(
            16 + self.knots_u.len() + self.knots_v.len() + 4 * self.points.len(),
        );
        v.push(Param::Int(128));
        v.push(Param::Int(to_i64(self.poles[0]) - 1));
        v.push(Param::Int(to_i64(self.poles[1]) - 1));
        v.push(Param::Int(to_i64(self.degree[0])));
        v.push(Param::Int(to_i64(self.degree[1])));
        for f in [
            self.closed[0],
            self.closed[1],
            self.polynomial,
            self.periodic[0],
            self.periodic[1],
        ] {
            v.push(Param::Int(f));
        }
        v.extend(self.knots_u.iter().map(|&x| Param::Real(x)));
        v.extend(self.knots_v.iter().map(|&x| Param::Real(x)));
        v.extend(self.weights.iter().map(|&x| Param::Real(x)));
        for q in &self.points {
            v.extend(q.iter().map(|&x| Param::Real(x)));
        }
        if let Some(r) = self.range {
            v.extend(r.iter().map(|&x| Param::Real(x)));
        }
        v
    }
}

impl Transform124 {
    /// Decodes a tokenized 124 record (12 reals; empty = 0).
    pub fn from_params(p: &Parameters<'_>) -> Result<Self, ParseError> {
        check_type(p, 124)?;
        check_present(p, 12, "124")?;
        let mut rows = [[0.0; 4]; 3];
        for (r, row) in rows.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = p.real(1 + 4 * r + c, "matrix element")?;
            }
        }
        Ok(Transform124 { rows, form: p.form })
    }

    /// Applies the map to a point: `R x + T`.
    pub fn apply(&self, x: [f64; 3]) -> [f64; 3] {
        let r = &self.rows;
        [
            r[0][0] * x[0] + r[0][1] * x[1] + r[0][2] * x[2] + r[0][3],
            r[1][0] * x[0] + r[1][1] * x[1] + r[1][2] * x[2] + r[1][3],
            r[2][0] * x[0] + r[2][1] * x[1] + r[2][2] * x[2] + r[2][3],
        ]
    }

    /// Applies the rotation part only (for directions such as a plane normal).
    pub fn apply_linear(&self, x: [f64; 3]) -> [f64; 3] {
        let r = &self.rows;
        [
            r[0][0] * x[0] + r[0][1] * x[1] + r[0][2] * x[2],
            r[1][0] * x[0] + r[1][1] * x[1] + r[1][2] * x[2],
            r[2][0] * x[0] + r[2][1] * x[1] + r[2][2] * x[2],
        ]
    }

    /// The parameters to write.
    pub fn to_params(&self) -> Vec<Param> {
        let mut v = vec![Param::Int(124)];
        for row in &self.rows {
            v.extend(row.iter().map(|&x| Param::Real(x)));
        }
        v
    }
}

/// A count as an IGES integer (counts of in-memory data are far below `i64::MAX`).
fn to_i64(n: usize) -> i64 {
    i64::try_from(n).unwrap_or(i64::MAX)
}
