//! Errors of the NURBS core.

/// Why a NURBS curve or surface could not be built, or an operation could not be done.
///
/// Every variant names the offending index or value, so a diagnostic can point at it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// The degree is 0 or above [`MAX_DEGREE`](super::MAX_DEGREE).
    #[error("degree {degree} is out of range 1..={max}")]
    BadDegree {
        /// The degree given.
        degree: usize,
        /// The largest degree supported.
        max: usize,
    },
    /// Fewer control points than degree + 1.
    #[error("{poles} control points are too few for degree {degree} (need at least {})", degree + 1)]
    TooFewPoles {
        /// Number of control points given.
        poles: usize,
        /// The degree.
        degree: usize,
    },
    /// The knot count is not poles + degree + 1.
    #[error("{knots} knots given, but {poles} control points of degree {degree} need {}", poles + degree + 1)]
    KnotCount {
        /// Number of knots given.
        knots: usize,
        /// Number of control points.
        poles: usize,
        /// The degree.
        degree: usize,
    },
    /// A knot is NaN or infinite.
    #[error("knot[{index}] = {value} is not finite")]
    NonFiniteKnot {
        /// Index in the flat knot vector.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A knot is smaller than its predecessor.
    #[error("knot[{index}] = {value} is smaller than knot[{}] = {previous}", index - 1)]
    DecreasingKnot {
        /// Index of the smaller knot.
        index: usize,
        /// Its value.
        value: f64,
        /// The previous knot's value.
        previous: f64,
    },
    /// A knot value repeats more often than allowed: degree + 1 at most anywhere, and at most
    /// degree strictly inside the domain (a higher interior multiplicity would break the
    /// curve apart; ISO 10303-42 `constraints_param_b_spline` and Open CASCADE both refuse it).
    #[error(
        "knot value {value} at index {index} has multiplicity {multiplicity}; at most {max} allowed there"
    )]
    Multiplicity {
        /// First index of the run.
        index: usize,
        /// The knot value.
        value: f64,
        /// How often it repeats.
        multiplicity: usize,
        /// The largest multiplicity allowed at that place.
        max: usize,
    },
    /// The valid domain `[u_p, u_{n+1}]` has zero length.
    #[error("empty parameter domain [{start}, {end}]")]
    EmptyDomain {
        /// `u_p`.
        start: f64,
        /// `u_{n+1}`.
        end: f64,
    },
    /// A control point coordinate is NaN or infinite.
    #[error("control point {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the control point (for surfaces, flattened u-major: `i * nv + j`).
        index: usize,
    },
    /// A weight is not a finite positive number.
    #[error("weight[{index}] = {value} is not finite and positive")]
    BadWeight {
        /// Index of the weight (for surfaces, flattened u-major: `i * nv + j`).
        index: usize,
        /// The value.
        value: f64,
    },
    /// The weight count differs from the control point count.
    #[error("{weights} weights given for {poles} control points")]
    WeightCount {
        /// Number of weights.
        weights: usize,
        /// Number of control points.
        poles: usize,
    },
    /// Control points have a dimension other than 2 or 3, or mixed dimensions.
    #[error("control point {index} has {found} coordinates; expected {expected}")]
    Dimension {
        /// Index of the first offending point.
        index: usize,
        /// Coordinates found.
        found: usize,
        /// Coordinates expected (2 or 3).
        expected: usize,
    },
    /// A surface's control net is not rectangular.
    #[error("control net row {row} has {found} points; row 0 has {expected}")]
    RaggedNet {
        /// The row index (along u).
        row: usize,
        /// Its length.
        found: usize,
        /// Length of row 0.
        expected: usize,
    },
    /// A parameter lies outside the valid domain.
    #[error("parameter {t} is outside the domain [{start}, {end}]")]
    OutOfDomain {
        /// The parameter given.
        t: f64,
        /// Domain start.
        start: f64,
        /// Domain end.
        end: f64,
    },
    /// An operation's argument is invalid (the message says which and why).
    #[error("{0}")]
    InvalidArgument(String),
    /// The caller's stop signal fired during a long operation (degree elevation polls it).
    #[error("the operation was stopped")]
    Stopped,
    /// An operation cannot be done within the requested tolerance (knot removal, degree
    /// reduction, join).
    #[error("{what}: error bound {bound:e} exceeds tolerance {tolerance:e}")]
    ToleranceExceeded {
        /// The operation.
        what: &'static str,
        /// The computed error bound.
        bound: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
}
