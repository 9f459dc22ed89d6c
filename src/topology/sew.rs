//! # Sewing loose faces into shells and solids
//!
//! Files of trimmed surfaces (IGES 144 with 142 boundaries, STEP face sets) give each face
//! its own boundary curves: two neighbouring faces meet along two copies of one edge. Sewing
//! makes them share it, as ISO 10303-42 clause 5 requires of a connected face set:
//! 0. the faces come in groups, each sewn on its own (a 402 group of a shell's trimmed
//!    surfaces, as Open CASCADE writes them): nothing below joins two groups;
//! 1. vertices closer than the tolerance become one (grid buckets of the tolerance's size);
//! 2. edges between the same two vertices whose curves coincide within the tolerance (the
//!    points of one at seven interior parameters lie on the other) become one edge; the
//!    coedges that used the other copy use it, with their direction and their pcurve carried
//!    over (by the affine parameter map when the copies are parameterised alike, else
//!    computed again on the face's surface, [`super::edge_pcurve`]);
//! 3. faces connected through shared edges form shells; orientations are propagated so that
//!    every shared edge is used once in each direction (clause 5, closed_shell); a shell in
//!    which every edge is shared so becomes closed and bounds a solid, turned outward when
//!    its volume comes out negative ([`Model::solid_volume`]); the other shells stay open
//!    and their edges used once are reported.
//!
//! Unused edges and vertices are removed at the end; the maps from old to new indices are
//! returned so that the reader can carry its provenance over.

use std::collections::BTreeMap;

/// The sewing's hash maps: foldhash's `quality` hasher (grid cells and ids far apart do not
/// share buckets), a fraction of SipHash's cost per lookup.
type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::quality::RandomState>;

use super::measure::{MODEL_EVALUATIONS, faces_outward};
use super::{Coedge, EdgeId, FaceId, Model, ShellId, SolidId, TopologyError, VertexId, check};
use crate::nurbs::project::invert_curve;
use crate::nurbs::vector::dist;
use crate::nurbs::{NurbsCurve, Point3};

/// What sewing did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sewing {
    /// Old vertex index -> new one (`None`: merged away and unused).
    pub vertex_map: Vec<Option<VertexId>>,
    /// Old edge index -> new one (`None`: merged into another and removed).
    pub edge_map: Vec<Option<EdgeId>>,
    /// Edges merged into another.
    pub merged_edges: usize,
    /// Shells built, closed ones first.
    pub shells: Vec<ShellId>,
    /// Solids built on the closed shells.
    pub solids: Vec<SolidId>,
    /// Edges (new indices) used by one face only, or inconsistently: where the faces do not
    /// close up.
    pub open_edges: Vec<EdgeId>,
    /// Coedges whose pcurve could not be carried over or re-projected (left without one).
    pub lost_pcurves: usize,
    /// Pairs of open edges that nearly coincide (ends and middles within a tenth of the
    /// shorter one's chord, but beyond the tolerance), with the largest of those
    /// distances: where the faces almost close, as opposed to the border of a surface
    /// model (ISO 10303-42 clause 5.4.28 open_shell; IGES 5.3 section 4.147, 514 form 2), whose open
    /// edges have no partner.
    pub gaps: Vec<(EdgeId, EdgeId, f64)>,
    /// Whether every candidate pair of open edges was compared for [`Sewing::gaps`] (false
    /// when more than 2^22 pairs overlap: then the gaps are not all known).
    pub gaps_complete: bool,
}

struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n).collect())
    }
    fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] != x {
            self.0[x] = self.0[self.0[x]];
            x = self.0[x];
        }
        x
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb)] = ra.min(rb);
        }
    }
}

/// Most pairs of open edges compared when looking for near misses ([`Sewing::gaps`]).
const MAX_GAP_TESTS: usize = 1 << 22;

/// Interior fractions at which edge curves are compared.
const FRACTIONS: [f64; 7] = [0.07, 0.2, 0.35, 0.5, 0.65, 0.8, 0.93];

/// How `b` runs along `a` when their curves coincide.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Match {
    /// Same points at the same fractions of their ranges: parameters related affinely.
    Affine { reversed: bool },
    /// Same point set, parameterised differently.
    Other { reversed: bool },
}

fn at_fraction(c: &NurbsCurve, (a, b): (f64, f64), f: f64) -> Point3 {
    c.point_at_unchecked(a + (b - a) * f)
}

/// Distance from `p` to the part `range` of `c`: the nearest of 64 samples, refined by
/// Newton steps on `(C(t) - p) . C'(t) = 0` (NURBS Book eq. 6.3).
fn distance_to(c: &NurbsCurve, range: (f64, f64), p: Point3) -> f64 {
    let n = 64;
    let mut best = (f64::INFINITY, range.0);
    for i in 0..=n {
        let t = range.0 + (range.1 - range.0) * i as f64 / n as f64;
        let d = dist(c.point_at_unchecked(t), p);
        if d < best.0 {
            best = (d, t);
        }
    }
    let mut t = best.1;
    for _ in 0..20 {
        let Ok(d) = c.derivatives(t, 2) else { break };
        let r = [d[0][0] - p[0], d[0][1] - p[1], d[0][2] - p[2]];
        let f = r[0] * d[1][0] + r[1] * d[1][1] + r[2] * d[1][2];
        let df = d[1].iter().map(|x| x * x).sum::<f64>()
            + r[0] * d[2][0]
            + r[1] * d[2][1]
            + r[2] * d[2][2];
        if df.abs() <= f64::MIN_POSITIVE {
            break;
        }
        let next = (t - f / df).clamp(range.0, range.1);
        if next == t {
            break;
        }
        t = next;
    }
    best.0.min(dist(c.point_at_unchecked(t), p))
}

/// Whether edges `a` and `b` (between the same vertices) are one curve within `tol`.
fn coincide(m: &Model, a: EdgeId, b: EdgeId, tol: f64) -> Option<Match> {
    let (ea, eb) = (&m.edges[a.0], &m.edges[b.0]);
    let mut directions = Vec::with_capacity(2);
    if ea.start == eb.start && ea.end == eb.end {
        directions.push(false);
    }
    if ea.start == eb.end && ea.end == eb.start {
        directions.push(true);
    }
    for &reversed in &directions {
        let affine = FRACTIONS.iter().all(|&f| {
            let g = if reversed { 1.0 - f } else { f };
            dist(
                at_fraction(&ea.curve, ea.range, f),
                at_fraction(&eb.curve, eb.range, g),
            ) <= tol
        });
        if affine {
            return Some(Match::Affine { reversed });
        }
    }
    // Not alike parameterised: every sample of a on b's curve, and b's on a's.
    let on = |x: &super::Edge, y: &super::Edge| {
        FRACTIONS
            .iter()
            .all(|&f| distance_to(&y.curve, y.range, at_fraction(&x.curve, x.range, f)) <= tol)
    };
    if !directions.is_empty() && on(ea, eb) && on(eb, ea) {
        // Direction: does b's point at 1/4 of its range lie nearer a's first or last half?
        let q = at_fraction(&eb.curve, eb.range, 0.25);
        let first = distance_to(&ea.curve, (ea.range.0, 0.5 * (ea.range.0 + ea.range.1)), q);
        let second = distance_to(&ea.curve, (0.5 * (ea.range.0 + ea.range.1), ea.range.1), q);
        let reversed = if directions.len() == 1 {
            directions[0]
        } else {
            second < first
        };
        return Some(Match::Other { reversed });
    }
    None
}

/// The pcurve of a coedge that used edge `from`, for edge `to` (its curve's parameter).
fn carried_pcurve(
    m: &Model,
    face: FaceId,
    pcurve: &NurbsCurve,
    from: EdgeId,
    to: EdgeId,
    how: Match,
) -> Option<NurbsCurve> {
    let (ef, et) = (&m.edges[from.0], &m.edges[to.0]);
    match how {
        Match::Affine { reversed } => {
            // t on `from` -> s on `to`: s = a0 + (t - b0) k (or from the other end).
            let (b0, b1) = ef.range;
            let (a0, a1) = et.range;
            let k = (a1 - a0) / (b1 - b0);
            let (d0, d1) = pcurve.domain();
            let map = |t: f64| {
                if reversed {
                    a1 - (t - b0) * k
                } else {
                    a0 + (t - b0) * k
                }
            };
            let (s0, s1) = (map(d0), map(d1));
            let out = if reversed {
                pcurve.reverse().ok()?.reparameterize(s1, s0).ok()?
            } else {
                pcurve.reparameterize(s0, s1).ok()?
            };
            Some(out)
        }
        Match::Other { .. } => {
            let surface = &m.faces.get(face.0)?.surface;
            super::edge_pcurve(surface, None, &et.curve, et.range, et.tolerance)
                .ok()
                .filter(|p| p.deviation <= et.tolerance)
                .map(|p| p.curve)
        }
    }
}

impl Model {
    /// Sews each group of `groups` (see the module) on its own: merges the vertices and
    /// the coinciding edges of a group's faces within `tolerance`, builds shells, and
    /// solids on the closed ones. Nothing is shared between two groups, so solids that
    /// touch (a bolt in its hole, two blocks face to face) stay apart when each is a group,
    /// as a 402 group of a shell's trimmed surfaces says they are (IGES 5.3 section 4.81).
    pub fn sew(&mut self, groups: &[Vec<FaceId>], tolerance: f64) -> Result<Sewing, TopologyError> {
        if !(tolerance > 0.0 && tolerance.is_finite()) {
            return Err(TopologyError::BadVertex {
                point: [f64::NAN; 3],
                tolerance,
            });
        }
        let mut report = Sewing::default();
        let mut faces: Vec<FaceId> = Vec::with_capacity(groups.iter().map(Vec::len).sum());
        // The group of each vertex and edge the faces use (the first group that uses it).
        let mut vertex_group: Vec<Option<usize>> = vec![None; self.vertices.len()];
        let mut edge_group: Vec<Option<usize>> = vec![None; self.edges.len()];
        for (g, list) in groups.iter().enumerate() {
            for f in list {
                let Some(face) = self.faces.get(f.0) else {
                    return Err(TopologyError::Missing {
                        what: "face",
                        index: f.0,
                    });
                };
                faces.push(*f);
                for c in face.loops.iter().flat_map(|l| &l.coedges) {
                    let (Some(slot), Some(e)) =
                        (edge_group.get_mut(c.edge.0), self.edges.get(c.edge.0))
                    else {
                        return Err(TopologyError::Missing {
                            what: "edge",
                            index: c.edge.0,
                        });
                    };
                    slot.get_or_insert(g);
                    for v in [e.start, e.end] {
                        if let Some(x) = vertex_group.get_mut(v.0) {
                            x.get_or_insert(g);
                        }
                    }
                }
            }
        }
        // 1. Vertices, within each group.
        let nv = self.vertices.len();
        let mut uf = UnionFind::new(nv);
        let mut grid: HashMap<(usize, [i64; 3]), Vec<usize>> = HashMap::default();
        let cell = |p: Point3| p.map(|x| (x / tolerance).floor() as i64);
        for (i, v) in self.vertices.iter().enumerate() {
            let Some(g) = vertex_group[i] else { continue };
            let c = cell(v.point);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(list) = grid.get(&(g, [c[0] + dx, c[1] + dy, c[2] + dz])) {
                            for &j in list {
                                if dist(self.vertices[j].point, v.point) <= tolerance {
                                    uf.union(i, j);
                                }
                            }
                        }
                    }
                }
            }
            grid.entry((g, c)).or_default().push(i);
        }
        for (k, e) in self.edges.iter_mut().enumerate() {
            if edge_group[k].is_none() {
                continue;
            }
            e.start = VertexId(uf.find(e.start.0));
            e.end = VertexId(uf.find(e.end.0));
            e.tolerance = e.tolerance.max(tolerance);
        }
        // 2. Edges used by the faces, grouped by their group and pair of vertices.
        let mut pairs: BTreeMap<(usize, VertexId, VertexId), Vec<EdgeId>> = BTreeMap::new();
        let mut seen = vec![false; self.edges.len()];
        for f in &faces {
            for c in self.faces[f.0].loops.iter().flat_map(|l| &l.coedges) {
                if std::mem::replace(&mut seen[c.edge.0], true) {
                    continue;
                }
                let e = &self.edges[c.edge.0];
                let g = edge_group[c.edge.0].unwrap_or(0);
                pairs
                    .entry((g, e.start.min(e.end), e.start.max(e.end)))
                    .or_default()
                    .push(c.edge);
            }
        }
        let mut replace: HashMap<EdgeId, (EdgeId, Match)> = HashMap::default();
        for list in pairs.values() {
            let mut kept: Vec<EdgeId> = Vec::new();
            for &e in list {
                let found = kept
                    .iter()
                    .find_map(|&k| coincide(self, k, e, tolerance).map(|how| (k, how)));
                match found {
                    Some(hit) => {
                        replace.insert(e, hit);
                    }
                    None => kept.push(e),
                }
            }
        }
        report.merged_edges = replace.len();
        for &f in &faces {
            let loops = std::mem::take(&mut self.faces[f.0].loops);
            let mut new_loops = loops.clone();
            for l in &mut new_loops {
                for c in &mut l.coedges {
                    let Some(&(to, how)) = replace.get(&c.edge) else {
                        continue;
                    };
                    let reversed = match how {
                        Match::Affine { reversed } | Match::Other { reversed } => reversed,
                    };
                    let pcurve = c
                        .pcurve
                        .as_ref()
                        .and_then(|p| carried_pcurve(self, f, p, c.edge, to, how));
                    if c.pcurve.is_some() && pcurve.is_none() {
                        report.lost_pcurves += 1;
                    }
                    *c = Coedge {
                        edge: to,
                        forward: c.forward != reversed,
                        pcurve,
                        pcurve_deviation: None,
                    };
                }
            }
            // An edge this face now uses twice (two boundary pieces merged into one seam edge):
            // its two coedges take the seam's two sides, as the loop continues.
            let surface = self.faces[f.0].surface.clone();
            let same_sense = self.faces[f.0].same_sense;
            let mut uses: BTreeMap<EdgeId, usize> = BTreeMap::new();
            for c in new_loops.iter().flat_map(|l| &l.coedges) {
                *uses.entry(c.edge).or_default() += 1;
            }
            for l in &mut new_loops {
                super::seam_sides_by_continuity(&surface, &mut l.coedges, same_sense, |e| {
                    uses.get(&e) == Some(&2)
                });
            }
            // The loops are checked again (closure through the merged vertices, pcurves).
            for (index, l) in new_loops.iter_mut().enumerate() {
                if let Err(e) = check::face_loop(self, f, index, &surface, l) {
                    self.faces[f.0].loops = loops;
                    return Err(e);
                }
            }
            self.faces[f.0].loops = new_loops;
        }
        // 3. Shells: faces connected through shared edges, orientations propagated.
        let mut users: BTreeMap<EdgeId, Vec<(usize, bool)>> = BTreeMap::new();
        for (k, f) in faces.iter().enumerate() {
            for c in self.faces[f.0].loops.iter().flat_map(|l| &l.coedges) {
                users.entry(c.edge).or_default().push((k, c.forward));
            }
        }
        let mut orientation: Vec<Option<bool>> = vec![None; faces.len()];
        let mut component = vec![usize::MAX; faces.len()];
        let mut conflicts: Vec<EdgeId> = Vec::new();
        let mut components = 0;
        for seed in 0..faces.len() {
            if orientation[seed].is_some() {
                continue;
            }
            orientation[seed] = Some(true);
            component[seed] = components;
            let mut stack = vec![seed];
            while let Some(k) = stack.pop() {
                let ok = orientation[k].unwrap_or(true);
                for c in self.faces[faces[k].0].loops.iter().flat_map(|l| &l.coedges) {
                    let effective = c.forward == ok;
                    for &(j, forward) in users.get(&c.edge).map_or(&[][..], Vec::as_slice) {
                        if j == k {
                            continue;
                        }
                        // The neighbour must use the edge the other way round.
                        let want = if effective { !forward } else { forward };
                        match orientation[j] {
                            None => {
                                orientation[j] = Some(want);
                                component[j] = components;
                                stack.push(j);
                            }
                            Some(o) if o != want => conflicts.push(c.edge),
                            Some(_) => {}
                        }
                    }
                }
            }
            components += 1;
        }
        conflicts.sort();
        conflicts.dedup();
        let mut closed_first: Vec<(bool, Vec<(FaceId, bool)>)> = Vec::new();
        for comp in 0..components {
            let members: Vec<(FaceId, bool)> = (0..faces.len())
                .filter(|&k| component[k] == comp)
                .map(|k| (faces[k], orientation[k].unwrap_or(true)))
                .collect();
            let closed = check::shell(self, ShellId(self.shells.len()), &members, false)?;
            closed_first.push((closed, members));
        }
        closed_first.sort_by_key(|(closed, _)| !*closed);
        // The closed shells' faces are measured (for their orientation) within one budget.
        let mut evaluations = (MODEL_EVALUATIONS, MODEL_EVALUATIONS);
        for (closed, members) in closed_first {
            let members = if closed {
                self.outward(members, &mut evaluations)
            } else {
                members
            };
            let shell = self.add_shell(members, closed)?;
            report.shells.push(shell);
            if closed {
                report.solids.push(self.add_solid(shell, Vec::new())?);
            }
        }
        // Edges used once, or twice the same way.
        for (&e, list) in &users {
            let forward = list
                .iter()
                .filter(|(k, f)| *f == orientation[*k].unwrap_or(true));
            let fwd = forward.count();
            if list.len() != 2 || fwd != 1 || conflicts.contains(&e) {
                report.open_edges.push(e);
            }
        }
        // 4. Compact: drop the merged edges and vertices.
        let merged: std::collections::HashSet<usize> = replace.keys().map(|e| e.0).collect();
        let rep: Vec<usize> = (0..nv).map(|i| uf.find(i)).collect();
        self.compact(&merged, &rep, &mut report);
        (report.gaps, report.gaps_complete) = self.gaps(&report.open_edges);
        Ok(report)
    }

    /// The pairs of `open` edges that nearly coincide (see [`Sewing::gaps`]): each end of
    /// one within `d` of an end of the other and the middle of one within `d` of the
    /// other's curve (NURBS Book section 6.1 point inversion, so parameterisations may
    /// differ), for `d <= 0.1 * ` the shorter chord. Candidates come from a sweep over the
    /// lowest x of each edge's ends; at most [`MAX_GAP_TESTS`] pairs are compared, and the
    /// flag says whether that was all of them.
    fn gaps(&self, open: &[EdgeId]) -> (Vec<(EdgeId, EdgeId, f64)>, bool) {
        // (edge, lowest x of its ends, ends, middle, chord) of each open edge.
        let mut keyed: Vec<(EdgeId, f64, [Point3; 2], Point3, f64)> = open
            .iter()
            .filter_map(|&e| {
                let edge = self.edges.get(e.0)?;
                let (a, b) = edge.range;
                let ends = [edge.curve.point_at(a).ok()?, edge.curve.point_at(b).ok()?];
                let middle = edge.curve.point_at(0.5 * (a + b)).ok()?;
                let chord = dist(ends[0], middle) + dist(middle, ends[1]);
                let low = ends[0][0].min(ends[1][0]);
                (chord.is_finite() && low.is_finite()).then_some((e, low, ends, middle, chord))
            })
            .collect();
        keyed.sort_by(|x, y| x.1.total_cmp(&y.1));
        let mut out = Vec::new();
        let mut tests = 0usize;
        for (i, &(ea, xa, a, ma, ca)) in keyed.iter().enumerate() {
            for &(eb, xb, b, _, cb) in &keyed[i + 1..] {
                if xb - xa > 0.1 * ca {
                    break;
                }
                if tests == MAX_GAP_TESTS {
                    return (out, false);
                }
                tests += 1;
                let limit = 0.1 * ca.min(cb);
                let ends = (dist(a[0], b[0]).max(dist(a[1], b[1])))
                    .min(dist(a[0], b[1]).max(dist(a[1], b[0])));
                if ends > limit {
                    continue;
                }
                let Some((_, middle)) = invert_curve(&self.edges[eb.0].curve, ma) else {
                    continue;
                };
                let d = ends.max(middle);
                if d <= limit {
                    out.push((ea, eb, d));
                }
            }
        }
        (out, true)
    }

    /// The members turned so that the enclosed volume is positive (when measurable), each
    /// face's flux signed as [`Model::solid_volume`] signs it; the measures spend from
    /// `evaluations` ([`Model::measure_face_sharing`]).
    fn outward(
        &self,
        members: Vec<(FaceId, bool)>,
        evaluations: &mut (u64, u64),
    ) -> Vec<(FaceId, bool)> {
        let mut flux = 0.0;
        for &(f, o) in &members {
            let Ok(m) = self.measure_face_sharing(&self.faces[f.0], evaluations) else {
                return members;
            };
            flux += if faces_outward(&self.faces[f.0], o) {
                m.flux
            } else {
                -m.flux
            };
        }
        if flux < 0.0 {
            members.into_iter().map(|(f, o)| (f, !o)).collect()
        } else {
            members
        }
    }

    /// Removes the edges merged into others and the vertices merged into others.
    fn compact(
        &mut self,
        merged: &std::collections::HashSet<usize>,
        vertex_rep: &[usize],
        report: &mut Sewing,
    ) {
        let mut edge_map = Vec::with_capacity(self.edges.len());
        let mut kept_edges = Vec::with_capacity(self.edges.len());
        for (i, e) in std::mem::take(&mut self.edges).into_iter().enumerate() {
            if merged.contains(&i) {
                edge_map.push(None);
            } else {
                edge_map.push(Some(EdgeId(kept_edges.len())));
                kept_edges.push(e);
            }
        }
        let mut vertex_map = Vec::with_capacity(self.vertices.len());
        let mut kept_vertices = Vec::with_capacity(self.vertices.len());
        for (i, v) in std::mem::take(&mut self.vertices).into_iter().enumerate() {
            if vertex_rep[i] == i {
                vertex_map.push(Some(VertexId(kept_vertices.len())));
                kept_vertices.push(v);
            } else {
                vertex_map.push(None);
            }
        }
        for e in &mut kept_edges {
            e.start = vertex_map[e.start.0].unwrap_or(e.start);
            e.end = vertex_map[e.end.0].unwrap_or(e.end);
        }
        for f in &mut self.faces {
            for c in f.loops.iter_mut().flat_map(|l| &mut l.coedges) {
                c.edge = edge_map[c.edge.0].unwrap_or(c.edge);
            }
            for v in &mut f.vertex_loops {
                let rep = vertex_rep.get(v.0).copied().unwrap_or(v.0);
                *v = vertex_map.get(rep).copied().flatten().unwrap_or(*v);
            }
        }
        for a in &mut self.assemblies {
            for inst in &mut a.instances {
                if let super::Part::Edge(e) = &mut inst.part {
                    *e = edge_map[e.0].unwrap_or(*e);
                }
            }
        }
        report.open_edges = report
            .open_edges
            .iter()
            .filter_map(|e| edge_map[e.0])
            .collect();
        self.edges = kept_edges;
        self.vertices = kept_vertices;
        report.edge_map = edge_map;
        report.vertex_map = vertex_map;
    }
}
