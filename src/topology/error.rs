//! Why a piece of topology was refused.

use super::{AssemblyId, EdgeId, FaceId, ShellId, VertexId};
use crate::nurbs::Point3;

/// A violated condition of the boundary representation, naming the pieces involved (the
/// reader maps the indices back to file entities and locations).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TopologyError {
    /// A referenced vertex, edge, face or shell does not exist.
    #[error("{what} {index} does not exist")]
    Missing {
        /// `vertex`, `edge`, `face`, `shell`, `solid` or `assembly`.
        what: &'static str,
        /// The index given.
        index: usize,
    },
    /// A vertex with a non-finite point or a negative tolerance.
    #[error("vertex at {point:?} with tolerance {tolerance} is not finite")]
    BadVertex {
        /// The point.
        point: Point3,
        /// The tolerance.
        tolerance: f64,
    },
    /// An edge's parameter range is empty, not finite, or outside its curve's domain.
    #[error("edge {edge:?}: range [{}, {}] is not an increasing part of the curve's domain [{}, {}]", range.0, range.1, domain.0, domain.1)]
    EdgeRange {
        /// The edge being built.
        edge: EdgeId,
        /// Its range.
        range: (f64, f64),
        /// The curve's domain.
        domain: (f64, f64),
    },
    /// An edge's curve ends too far from a vertex (ISO 10303-42 clause 5, edge_curve).
    #[error(
        "edge {edge:?}: the curve at its {end} is {distance:e} from vertex {vertex:?} (tolerance {tolerance:e})"
    )]
    EdgeMissesVertex {
        /// The edge being built.
        edge: EdgeId,
        /// The vertex.
        vertex: VertexId,
        /// `start` or `end`.
        end: &'static str,
        /// Distance found.
        distance: f64,
        /// Tolerance allowed.
        tolerance: f64,
    },
    /// A loop with no edges, or whose edges do not chain head to tail through shared
    /// vertices (ISO 10303-42 clause 5, edge_loop).
    #[error(
        "face {face:?}, loop {index}: coedge {coedge} ends at vertex {end:?} but the next one starts at {next:?}"
    )]
    LoopOpen {
        /// The face being built.
        face: FaceId,
        /// Index of the loop in the face.
        index: usize,
        /// Index of the coedge whose end does not meet the next start.
        coedge: usize,
        /// Where it ends.
        end: Option<VertexId>,
        /// Where the next starts.
        next: Option<VertexId>,
    },
    /// A parameter-space curve that does not lie on its 3-D edge curve through the surface.
    #[error(
        "face {face:?}, loop {index}, coedge {coedge}: surface(pcurve(t)) is {deviation:e} from the edge curve (tolerance {tolerance:e})"
    )]
    PcurveDeviates {
        /// The face being built.
        face: FaceId,
        /// Loop index.
        index: usize,
        /// Coedge index.
        coedge: usize,
        /// Largest distance found.
        deviation: f64,
        /// The edge's tolerance.
        tolerance: f64,
    },
    /// A shell declared closed that uses some edges other than twice in opposite
    /// directions.
    #[error(
        "shell {shell:?} is declared closed but {count} edges are not used exactly twice in opposite directions (first: {edges:?})"
    )]
    ShellNotClosed {
        /// The shell being built.
        shell: ShellId,
        /// How many edges break it.
        count: usize,
        /// The first few of them.
        edges: Vec<EdgeId>,
    },
    /// A solid bounded by a shell that is not closed.
    #[error("a solid's shell {shell:?} is not closed")]
    SolidShellOpen {
        /// The shell.
        shell: ShellId,
    },
    /// Assemblies that contain each other.
    #[error("assemblies contain each other: {chain:?}")]
    AssemblyCycle {
        /// The chain that closes the cycle.
        chain: Vec<AssemblyId>,
    },
    /// A placement that is not a proper rigid-or-scaling map (not finite, or its linear part
    /// has a determinant <= 0: a mirror would turn the solids inside out).
    #[error("placement {placement:?} is not usable: {reason}")]
    PlacementInvalid {
        /// The 3x4 matrix.
        placement: [[f64; 4]; 3],
        /// Why.
        reason: String,
    },
    /// Flattening an assembly would give more instances or deeper nesting than allowed.
    #[error("assembly {root:?} expands beyond {limit} {what}")]
    AssemblyTooLarge {
        /// The assembly flattened.
        root: AssemblyId,
        /// `instances` or `levels`.
        what: &'static str,
        /// The limit.
        limit: usize,
    },
}
