//! The checks of the constructors in [`super::Model`].

use super::{EdgeId, FaceId, Loop, Model, ShellId, TopologyError, VertexId};
use crate::nurbs::vector::dist;
use crate::nurbs::{NurbsCurve, NurbsSurface};

fn vertex(m: &Model, v: VertexId) -> Result<&super::Vertex, TopologyError> {
    m.vertices.get(v.0).ok_or(TopologyError::Missing {
        what: "vertex",
        index: v.0,
    })
}

/// ISO 10303-42 clause 5, edge_curve: the curve passes through both vertices.
pub(super) fn edge(
    m: &Model,
    id: EdgeId,
    curve: &NurbsCurve,
    range: (f64, f64),
    start: VertexId,
    end: VertexId,
    tolerance: f64,
) -> Result<(), TopologyError> {
    let domain = curve.domain();
    let ok = range.0.is_finite()
        && range.1.is_finite()
        && range.0 < range.1
        && domain.0 <= range.0
        && range.1 <= domain.1;
    if !ok {
        return Err(TopologyError::EdgeRange {
            edge: id,
            range,
            domain,
        });
    }
    for (v, t, which) in [(start, range.0, "start"), (end, range.1, "end")] {
        let vx = vertex(m, v)?;
        let allowed = tolerance.max(vx.tolerance);
        let d = dist(curve.point_at_unchecked(t), vx.point);
        if d.is_nan() || d > allowed {
            return Err(TopologyError::EdgeMissesVertex {
                edge: id,
                vertex: v,
                end: which,
                distance: d,
                tolerance: allowed,
            });
        }
    }
    Ok(())
}

/// Samples per edge span for the pcurve check.
const PCURVE_SAMPLES: usize = 16;

/// ISO 10303-42 clause 5, edge_loop (closure through shared vertices) and the pcurve /
/// 3-D curve agreement of every coedge that has one.
pub(super) fn face_loop(
    m: &Model,
    face: FaceId,
    index: usize,
    surface: &NurbsSurface,
    l: &mut Loop,
) -> Result<(), TopologyError> {
    let n = l.coedges.len();
    if n == 0 {
        return Err(TopologyError::LoopOpen {
            face,
            index,
            coedge: 0,
            end: None,
            next: None,
        });
    }
    let mut ends = Vec::with_capacity(n);
    for c in &l.coedges {
        ends.push(m.coedge_ends(c).ok_or(TopologyError::Missing {
            what: "edge",
            index: c.edge.0,
        })?);
    }
    for i in 0..n {
        let (end, next) = (ends[i].1, ends[(i + 1) % n].0);
        if end != next {
            return Err(TopologyError::LoopOpen {
                face,
                index,
                coedge: i,
                end: Some(end),
                next: Some(next),
            });
        }
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    for (k, c) in l.coedges.iter_mut().enumerate() {
        let Some(p) = &c.pcurve else { continue };
        let e = &m.edges[c.edge.0];
        let (pa, pb) = p.domain();
        // Measured where the pcurve was made ([`super::edge_pcurve`], more densely than
        // here), or sampled now.
        let mut worst: f64 = c.pcurve_deviation.unwrap_or(0.0);
        let samples = if c.pcurve_deviation.is_some() {
            0
        } else {
            PCURVE_SAMPLES + 1
        };
        for s in 0..samples {
            let t = if s == PCURVE_SAMPLES {
                e.range.1
            } else {
                e.range.0 + (e.range.1 - e.range.0) * (s as f64 / PCURVE_SAMPLES as f64)
            };
            // Evaluated at the nearest parameters inside the pcurve's and the surface's
            // domains: a pcurve that leaves them shows as the distance it causes.
            let [u, v, _] = p.point_at_unchecked(t.clamp(pa, pb));
            let on = surface.point_at_unchecked(u.clamp(u0, u1), v.clamp(v0, v1));
            let d = dist(on, e.curve.point_at_unchecked(t));
            worst = worst.max(d);
        }
        if worst.is_nan() || worst > e.tolerance {
            return Err(TopologyError::PcurveDeviates {
                face,
                index,
                coedge: k,
                deviation: worst,
                tolerance: e.tolerance,
            });
        }
        c.pcurve_deviation = Some(worst);
    }
    Ok(())
}

/// How many edges a `ShellNotClosed` error lists.
const LISTED_EDGES: usize = 8;

/// Whether the faces use every edge exactly twice in opposite directions (ISO 10303-42
/// closed_shell); with `declared_closed`, anything else is an error.
pub(super) fn shell(
    m: &Model,
    id: ShellId,
    faces: &[(FaceId, bool)],
    declared_closed: bool,
) -> Result<bool, TopologyError> {
    // Every use of an edge, (edge, whether with the face's orientation), sorted: the uses
    // of one edge are then a run (a sort of one list, no tree node per edge).
    let mut uses: Vec<(EdgeId, bool)> = Vec::new();
    for &(f, orientation) in faces {
        let face = m.faces.get(f.0).ok_or(TopologyError::Missing {
            what: "face",
            index: f.0,
        })?;
        for l in &face.loops {
            uses.extend(l.coedges.iter().map(|c| (c.edge, c.forward == orientation)));
        }
    }
    uses.sort_unstable();
    // An edge is bad unless it is used exactly once each way.
    let bad: Vec<EdgeId> = uses
        .chunk_by(|a, b| a.0 == b.0)
        .filter(|run| !matches!(run, [(_, false), (_, true)]))
        .filter_map(|run| run.first().map(|u| u.0))
        .collect();
    // Without any edge (faces bounded by their surfaces alone, as a sphere whose only bound
    // is a vertex loop) the shell is closed when each face's surface closes on itself.
    let closed = bad.is_empty()
        && (!uses.is_empty()
            || (!faces.is_empty()
                && faces
                    .iter()
                    .all(|(f, _)| m.faces.get(f.0).is_some_and(|x| surface_closes(&x.surface)))));
    if declared_closed && !closed {
        return Err(TopologyError::ShellNotClosed {
            shell: id,
            count: bad.len(),
            edges: bad.into_iter().take(LISTED_EDGES).collect(),
        });
    }
    Ok(closed)
}

/// Samples per boundary for [`surface_closes`].
const BOUNDARY_SAMPLES: usize = 16;

/// Whether a surface bounds a region by itself (ISO 10303-42 closed_shell of faces without
/// edges): in each direction the two boundary curves coincide or each is a single point
/// (a pole), within 1e-9 of the control net's size.
fn surface_closes(surface: &NurbsSurface) -> bool {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let tol = crate::nurbs::bounding_box_diagonal(surface.control_points().as_slice()) * 1e-9;
    let side = |along_u: bool, at: f64| -> Vec<crate::nurbs::Point3> {
        (0..=BOUNDARY_SAMPLES)
            .map(|k| {
                let t = k as f64 / BOUNDARY_SAMPLES as f64;
                if along_u {
                    surface.point_at_unchecked(u0 + (u1 - u0) * t, at)
                } else {
                    surface.point_at_unchecked(at, v0 + (v1 - v0) * t)
                }
            })
            .collect()
    };
    let closes = |a: Vec<crate::nurbs::Point3>, b: Vec<crate::nurbs::Point3>| {
        let same = a.iter().zip(&b).all(|(p, q)| dist(*p, *q) <= tol);
        let point = |c: &[crate::nurbs::Point3]| c.iter().all(|p| dist(*p, c[0]) <= tol);
        same || (point(&a) && point(&b))
    };
    closes(side(false, u0), side(false, u1)) && closes(side(true, v0), side(true, v1))
}
