//! The JSON form of curves and surfaces, shared by the CLI and the HTTP API.
//!
//! Curve: `{"degree":3,"knots":[...],"control_points":[[x,y,z],...],"weights":[...]}`
//! (`weights` omitted when polynomial; points with 2 coordinates make a 2-D curve). Instead
//! of `knots`, a curve may give its knots in knot-interval form (seed 003, see
//! [`KnotIntervals`]): `"knot_intervals":[...]` (control points + degree - 2 values),
//! optionally `"knot_origin":u0` (default 0) and `"outer_knot_intervals":[a,b]` (default
//! `[0,0]`, a clamped end); [`KnotIntervalForm`] writes that form.
//!
//! Surface: `{"degree_u":p,"degree_v":q,"knots_u":[...],"knots_v":[...],
//! "control_points":[[[x,y,z],...],...],"weights":[[...],...]}` with
//! `control_points[i][j]`, `i` along u and `j` along v.
//!
//! Deserialisation goes through the checked constructors, so JSON can never build an
//! invalid curve or surface; the error message is the constructor's.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::knot_intervals::KnotIntervals;
use super::{Geometry, GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCurve {
    degree: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    knots: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    knot_origin: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    outer_knot_intervals: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    knot_intervals: Option<Vec<f64>>,
    control_points: Vec<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    weights: Option<Vec<f64>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSurface {
    degree_u: usize,
    degree_v: usize,
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    control_points: Vec<Vec<Vec<f64>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    weights: Option<Vec<Vec<f64>>>,
}

fn to_coords(p: &Point3, dimension: usize) -> Vec<f64> {
    p[..dimension].to_vec()
}

/// Converts JSON coordinate lists to points, checking one common dimension of 2 or 3.
fn from_coords<'a>(
    lists: impl Iterator<Item = &'a Vec<f64>>,
) -> Result<(Vec<Point3>, usize), GeometryError> {
    let mut dimension = None;
    let mut out = Vec::new();
    for (index, c) in lists.enumerate() {
        let d = *dimension.get_or_insert(c.len());
        if c.len() != d || !(d == 2 || d == 3) {
            return Err(GeometryError::Dimension {
                index,
                found: c.len(),
                expected: if d == 2 { 2 } else { 3 },
            });
        }
        out.push([c[0], c[1], if d == 3 { c[2] } else { 0.0 }]);
    }
    Ok((out, dimension.unwrap_or(3)))
}

impl TryFrom<RawCurve> for NurbsCurve {
    type Error = GeometryError;
    fn try_from(r: RawCurve) -> Result<Self, GeometryError> {
        let (points, dimension) = from_coords(r.control_points.iter())?;
        let knots = match (r.knots, r.knot_intervals) {
            (Some(knots), None) => {
                if r.knot_origin.is_some() || r.outer_knot_intervals.is_some() {
                    return Err(GeometryError::InvalidArgument(
                        "knot_origin and outer_knot_intervals go with knot_intervals, not \
                         with knots"
                            .into(),
                    ));
                }
                knots
            }
            (None, Some(intervals)) => {
                // n + p - 1 intervals for n + 1 poles (seed 003; see `knot_intervals`).
                let expected = (points.len() + r.degree).checked_sub(2);
                if expected != Some(intervals.len()) {
                    return Err(GeometryError::InvalidArgument(format!(
                        "knot_intervals has {} values, but {} control points of degree {} \
                         need {} (control points + degree - 2)",
                        intervals.len(),
                        points.len(),
                        r.degree,
                        expected.map_or_else(|| "none".to_owned(), |e| e.to_string())
                    )));
                }
                KnotIntervals {
                    origin: r.knot_origin.unwrap_or(0.0),
                    outer: r.outer_knot_intervals.unwrap_or([0.0, 0.0]),
                    intervals,
                }
                .to_knots()?
            }
            (Some(_), Some(_)) => {
                return Err(GeometryError::InvalidArgument(
                    "a curve has either knots or knot_intervals, not both".into(),
                ));
            }
            (None, None) => {
                return Err(GeometryError::InvalidArgument(
                    "a curve needs knots (or knot_intervals)".into(),
                ));
            }
        };
        NurbsCurve::with_dimension(r.degree, knots, points, r.weights, dimension)
    }
}

impl TryFrom<RawSurface> for NurbsSurface {
    type Error = GeometryError;
    fn try_from(r: RawSurface) -> Result<Self, GeometryError> {
        let nu = r.control_points.len();
        let nv = r.control_points.first().map_or(0, Vec::len);
        for (row, list) in r.control_points.iter().enumerate() {
            if list.len() != nv {
                return Err(GeometryError::RaggedNet {
                    row,
                    found: list.len(),
                    expected: nv,
                });
            }
        }
        let (points, dimension) = from_coords(r.control_points.iter().flatten())?;
        let points = Grid::from_u_major(nu, nv, points)
            .ok_or_else(|| GeometryError::InvalidArgument("control net shape".into()))?;
        let weights = match r.weights {
            None => None,
            Some(rows) => {
                if rows.len() != nu || rows.iter().any(|w| w.len() != nv) {
                    return Err(GeometryError::WeightCount {
                        weights: rows.iter().map(Vec::len).sum(),
                        poles: nu * nv,
                    });
                }
                Grid::from_u_major(nu, nv, rows.into_iter().flatten().collect())
            }
        };
        NurbsSurface::with_dimension(
            r.degree_u, r.degree_v, r.knots_u, r.knots_v, points, weights, dimension,
        )
    }
}

impl RawCurve {
    /// The JSON form of `c`, its knots as a knot vector or in knot-interval form.
    ///
    /// Errors when a knot cannot be written exactly as an interval (see
    /// [`KnotIntervals`]: no `f64` interval sums from the previous knot to it).
    fn of(c: &NurbsCurve, intervals: bool) -> Result<Self, String> {
        let (knots, knot_origin, outer_knot_intervals, knot_intervals) = if intervals {
            let k = c.knot_intervals();
            if let Some(i) = k.inexact_knot(c.knots()) {
                return Err(format!(
                    "knot[{i}] = {:e} does not come back from knot-interval form (no f64 \
                     difference from the previous knot sums back to it, or the difference \
                     overflows); write this curve with its knot vector",
                    c.knots().get(i).copied().unwrap_or(f64::NAN)
                ));
            }
            let outer = (k.outer != [0.0, 0.0]).then_some(k.outer);
            (None, Some(k.origin), outer, Some(k.intervals))
        } else {
            (Some(c.knots().to_vec()), None, None, None)
        };
        Ok(RawCurve {
            degree: c.degree(),
            knots,
            knot_origin,
            outer_knot_intervals,
            knot_intervals,
            control_points: c
                .control_points()
                .iter()
                .map(|p| to_coords(p, c.dimension()))
                .collect(),
            weights: c.weights().map(<[f64]>::to_vec),
        })
    }
}

impl From<&NurbsSurface> for RawSurface {
    fn from(s: &NurbsSurface) -> Self {
        let net = s.control_points();
        RawSurface {
            degree_u: s.degree_u(),
            degree_v: s.degree_v(),
            knots_u: s.knots_u().to_vec(),
            knots_v: s.knots_v().to_vec(),
            control_points: (0..net.nu())
                .map(|i| {
                    net.row(i)
                        .iter()
                        .map(|p| to_coords(p, s.dimension()))
                        .collect()
                })
                .collect(),
            weights: s
                .weights()
                .map(|w| (0..w.nu()).map(|i| w.row(i).to_vec()).collect()),
        }
    }
}

impl Serialize for NurbsCurve {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        RawCurve::of(self, false)
            .map_err(serde::ser::Error::custom)?
            .serialize(s)
    }
}

/// A geometry serialised with a curve's knots in knot-interval form (seed 003:
/// `knot_origin`, `knot_intervals` and, when not both zero, `outer_knot_intervals`; see
/// [`KnotIntervals`]) instead of `knots`. A surface is written as usual, with knot
/// vectors. Reading accepts either form.
pub struct KnotIntervalForm<'a>(pub &'a Geometry);

impl Serialize for KnotIntervalForm<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0 {
            Geometry::Curve(c) => RawCurve::of(c, true)
                .map_err(serde::ser::Error::custom)?
                .serialize(s),
            Geometry::Surface(f) => f.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for NurbsCurve {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        NurbsCurve::try_from(RawCurve::deserialize(d)?).map_err(serde::de::Error::custom)
    }
}

impl Serialize for NurbsSurface {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        RawSurface::from(self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for NurbsSurface {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        NurbsSurface::try_from(RawSurface::deserialize(d)?).map_err(serde::de::Error::custom)
    }
}

impl Serialize for Geometry {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Geometry::Curve(c) => c.serialize(s),
            Geometry::Surface(f) => f.serialize(s),
        }
    }
}

/// Which shape a geometry object has: a surface names `degree_u`, a curve `degree`.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawGeometry {
    Surface(RawSurface),
    Curve(RawCurve),
}

impl<'de> Deserialize<'de> for Geometry {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        match RawGeometry::deserialize(d).map_err(|_| {
            serde::de::Error::custom(
                "expected a curve {degree, knots (or knot_intervals[, knot_origin, \
                 outer_knot_intervals]), control_points[, weights]} or a surface \
                 {degree_u, degree_v, knots_u, knots_v, control_points[, weights]}",
            )
        })? {
            RawGeometry::Curve(c) => NurbsCurve::try_from(c)
                .map(Geometry::Curve)
                .map_err(serde::de::Error::custom),
            RawGeometry::Surface(s) => NurbsSurface::try_from(s)
                .map(Geometry::Surface)
                .map_err(serde::de::Error::custom),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_json_round_trip_keeps_dimension_and_weights() {
        let json = r#"{"degree":2,"knots":[0,0,0,1,1,1],"control_points":[[1,0],[1,1],[0,1]],"weights":[1,0.7071067811865476,1]}"#;
        let c: NurbsCurve = serde_json::from_str(json).unwrap();
        assert_eq!(c.dimension(), 2);
        let back = serde_json::to_string(&c).unwrap();
        let c2: NurbsCurve = serde_json::from_str(&back).unwrap();
        assert_eq!(c, c2);
        assert!(!back.contains("[1.0,0.0,0.0]"));
    }

    #[test]
    fn invalid_json_geometry_is_refused_with_the_constructor_message() {
        let json =
            r#"{"degree":2,"knots":[0,0,0,1,0.5,1],"control_points":[[1,0,0],[1,1,0],[0,1,0]]}"#;
        let err = serde_json::from_str::<NurbsCurve>(json)
            .unwrap_err()
            .to_string();
        assert!(err.contains("knot[4]"), "{err}");
        let json = r#"{"degree_u":1,"degree_v":1,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],
            "control_points":[[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}"#;
        assert!(matches!(
            serde_json::from_str::<Geometry>(json).unwrap(),
            Geometry::Surface(_)
        ));
    }
}
