//! # STEP records <-> NURBS model
//!
//! [`read()`] turns every ISO 10303-42 B-spline curve and surface of an AP203/AP214/AP242
//! file (any subtype, rational or not, simple or complex instances, 2-D pcurves included)
//! and every line, conic, polyline, trimmed, composite and surface curve, elementary and
//! swept surface and rectangular trimmed surface (`geometry`: exact NURBS, bounded by their
//! use, parameter maps in README) into [`Entity`](super::Entity)s, with the file's length
//! and plane-angle units; [`write()`] produces a file Open CASCADE / FreeCAD imports
//! (spec.md c.5), labelling each entity's form only when [`form_warnings`]'s check agrees.
//!
//! Diagnostic codes emitted here:
//!
//! | code | severity | meaning |
//! |---|---|---|
//! | `step.syntax` | error | a statement or instance body does not parse (skipped) |
//! | `step.structure` | error/warning | duplicate id, missing `END-ISO-10303-21;`, trailing input, skipped edition-3 section |
//! | `step.schema` | error | a B-spline's attribute has the wrong type or count |
//! | `step.reference` | error | a dangling control point reference, or a reference to a non-point |
//! | `step.reference_cycle` | error | a reference cycle through a B-spline |
//! | `knot_count_mismatch` | error | sum of multiplicities is not poles + degree + 1 |
//! | `knots.invalid` | error | multiplicities not positive, lists of unequal length, implicit knots impossible |
//! | `weights.invalid` | error | weight count differs from the poles, or a weight is not > 0 |
//! | `points.invalid` | error | control points with mixed or unsupported dimensions |
//! | `geometry.invalid` | error | the NURBS constructor refused the data |
//! | `limit.degree`, `limit.poles` | error | above [`Limits`](nurbsx_parsers::Limits) |
//! | `flag_mismatch` | warning (info for `.F.` on closed geometry) | `closed_curve`/`u_closed`/`v_closed` disagrees with the geometry |
//! | `units` | info | the file's length unit |
//! | `units_converted` | info | coordinates scaled to the requested unit |
//! | `units_missing`, `units_ambiguous`, `units_unknown` | warning | no / several / unrecognised length units; no plane-angle unit (radians assumed); an unreadable length uncertainty |
//! | `step.uncertainty_ignored` | warning | the file's length uncertainty is above 1e-3 of the part's size; the topology is read within 1e-7 of the size |
//! | `geometry.unbounded` | warning | an unbounded line, parabola, hyperbola or surface that no trim, edge or face bounds: not represented |
//! | `geometry.unsupported` | error | an OFFSET_CURVE/OFFSET_SURFACE (no exact rational form), or a point trim on a B-spline without a parameter |
//! | `presentation.not_carried` | warning | colours and styles (STYLED_ITEM), layers (PRESENTATION_LAYER_ASSIGNMENT) and properties (PROPERTY_DEFINITION) of the file, counted in one diagnostic: not carried into the model or its output |
//! | `pcurve.not_converted` | warning | `geometry_only`: analytic parameter-space curves of PCURVEs (one diagnostic listing them); a whole-part reading computes every coedge's pcurve on the NURBS surface instead |
//! | `trim.parameter_outside` | warning | a trim parameter outside an open B-spline basis's domain (the trim point at a basis end, or the clamped value, is used) |
//! | `trim.parameter_mismatch` | warning | a trim's parameter and point disagree (Open CASCADE writes parabola trims in its own parameter): the point's exact inverse is used |
//! | `limit.nesting_depth` | error | curves or surfaces built on each other more than 16 levels deep |
//! | `step.form_unspecified` | warning (writer) | an entity's declared kind disagrees with its geometry: written `.UNSPECIFIED.` |
//! | `topology.loop_open`, `topology.edge_vertex`, `topology.edge_range`, `topology.missing`, `topology.vertex_invalid` | error | a face loop, edge or vertex refused by the topology checks, or one whose parts could not be read: skipped |
//! | `topology.shell_open` | error | a CLOSED_SHELL that does not close: kept as an open shell |
//! | `topology.solid_shell_open` | error | a solid on a shell that is not closed: skipped |
//! | `topology.pcurve_deviates` | error | a projected pcurve the face check refuses: the face is kept without pcurves |
//! | `pcurve.not_computed` | warning | coedges whose 3-D edge did not project onto the face surface within the edge tolerance (one diagnostic) |
//! | `topology.not_read` | warning | `geometry_only`: how many faces, edges, shells and solids were left out |
//! | `assembly.placed` | info | assembly placements applied: how many part instances were placed in root coordinates |
//! | `assembly.refused` | error | a product structure that contains itself, nests deeper than 64 levels or expands to more than 100,000 instances: no placement is applied, every part is kept once in its own coordinates |
//! | `assembly.not_placed` | error/warning | a usage whose placement is not an ITEM_DEFINED_TRANSFORMATION of axis placements, or a MAPPED_ITEM without a REPRESENTATION_MAP: that instance is not placed |
//! | `assembly.placement_missing` | warning | a usage with no CONTEXT_DEPENDENT_SHAPE_REPRESENTATION: placed in its own coordinates |
//! | `assembly.geometry_not_placed` | warning | GEOMETRIC_SETs in placed products holding points, surfaces or unreadable curves: those are kept once, unplaced (their curves are free edges, placed) |

mod assembly;
mod geometry;
mod implicit;
mod read;
mod topology;
mod units;
mod write;

pub use implicit::{KnotForm, implicit_knots, knot_form};
pub use read::read;
pub use write::{assembly_warnings, form_warnings, range_warnings, write, write_reporting};

/// Closure tolerance shared by the reader (checking `closed_curve`/`u_closed` against the
/// data) and the writer (computing them), so the two always agree: 1e-9 of the control
/// polygon's bounding-box diagonal, at least 1e-12 ("equal up to rounding" at the
/// geometry's own scale).
fn closure_tolerance(points: &[crate::nurbs::Point3]) -> f64 {
    (crate::nurbs::bounding_box_diagonal(points) * 1e-9).max(1e-12)
}

/// `#id`: how the model names STEP instance `id` (the entity instance name of ISO 10303-21
/// clause 6.3.4). Every converted item and origin carries one, so it is built inline (no
/// allocation: a [`Label`](super::Label) holds up to 24 bytes, and `#` with 20 digits is 21) and without
/// the formatting machinery.
fn instance_label(id: u64) -> super::Label {
    // `#` and up to 20 digits, written from the end.
    let mut text = [0u8; 21];
    let mut start = text.len();
    let mut n = id;
    loop {
        start -= 1;
        // n % 10 < 10: the cast keeps it.
        text[start] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    start -= 1;
    text[start] = b'#';
    // ASCII, so always text; copied inline.
    std::str::from_utf8(&text[start..]).map_or_else(|_| super::Label::default(), super::Label::new)
}

/// The instance a label names: `N` for `#N` as [`instance_label`] writes it (decimal
/// digits, no leading zero); `None` for any other label.
fn instance_of(label: &str) -> Option<u64> {
    let digits = label.strip_prefix('#')?;
    let canonical =
        digits.bytes().all(|b| b.is_ascii_digit()) && (digits == "0" || !digits.starts_with('0'));
    canonical.then(|| digits.parse().ok()).flatten()
}

#[cfg(test)]
mod label_tests {
    /// The label agrees with the formatting machinery's decimal digits at the ends of the
    /// range and across each power of ten.
    #[test]
    fn instance_labels_are_the_decimal_ids() {
        let mut ids = vec![0, 1, 9, 10, 99, 100, u64::MAX - 1, u64::MAX];
        for k in 1..20u32 {
            let p = 10u64.pow(k);
            ids.extend([p - 1, p, p + 1]);
        }
        for id in ids {
            let label = super::instance_label(id);
            assert_eq!(label, format!("#{id}"));
            assert_eq!(super::instance_of(&label), Some(id));
            // Every label fits inline: none is a heap allocation.
            assert!(!label.is_heap_allocated(), "{label}");
        }
        // Labels of no one instance, or not as the reader writes it.
        for other in [
            "#",
            "#007",
            "#12@#3",
            "D5",
            "12",
            "#-1",
            "#18446744073709551616",
        ] {
            assert_eq!(super::instance_of(other), None, "{other}");
        }
    }
}
