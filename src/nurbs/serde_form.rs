//! The JSON form of curves and surfaces, shared by the CLI and the HTTP API.
//!
//! Curve: `{"degree":3,"knots":[...],"control_points":[[x,y,z],...],"weights":[...]}`
//! (`weights` omitted when polynomial; points with 2 coordinates make a 2-D curve).
//!
//! Surface: `{"degree_u":p,"degree_v":q,"knots_u":[...],"knots_v":[...],
//! "control_points":[[[x,y,z],...],...],"weights":[[...],...]}` with
//! `control_points[i][j]`, `i` along u and `j` along v.
//!
//! Deserialisation goes through the checked constructors, so JSON can never build an
//! invalid curve or surface; the error message is the constructor's.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{Geometry, GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCurve {
    degree: usize,
    knots: Vec<f64>,
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
        NurbsCurve::with_dimension(r.degree, r.knots, points, r.weights, dimension)
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

impl From<&NurbsCurve> for RawCurve {
    fn from(c: &NurbsCurve) -> Self {
        RawCurve {
            degree: c.degree(),
            knots: c.knots().to_vec(),
            control_points: c
                .control_points()
                .iter()
                .map(|p| to_coords(p, c.dimension()))
                .collect(),
            weights: c.weights().map(<[f64]>::to_vec),
        }
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
        RawCurve::from(self).serialize(s)
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
                "expected a curve {degree, knots, control_points[, weights]} or a surface \
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
