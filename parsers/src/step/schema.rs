//! Typed records for the ISO 10303-42 B-spline entities, `CARTESIAN_POINT`, the ISO
//! 10303-41 unit entities and the ISO 10303-43 representation context.
//!
//! Attributes are read by **name**, from tables transcribed from the EXPRESS definitions
//! (spec.md c.2): each entity data type lists only the attributes it declares itself
//! ([`OWN_ATTRIBUTES`]); a simple instance carries the attributes of its whole supertype
//! chain in order ([`SUPERTYPE_CHAINS`]: `name` from `REPRESENTATION_ITEM` first), a complex
//! instance one partial record per entity data type, in any order. Both shapes go through
//! [`Attributes`], so `B_SPLINE_CURVE_WITH_KNOTS('NONE',...)`, `...('',...)` and the
//! external-mapping form `( BOUNDED_CURVE() B_SPLINE_CURVE(...) ... )` read identically.
//!
//! These records check what the schema's *types* require (an INTEGER degree, a list of
//! references, a LOGICAL...). Geometric rules (knot counts, weights > 0) are the exchange
//! layer's job, which turns records into NURBS.

use std::borrow::Cow;

use super::ast::{Body, Instance, Parameter};
use super::error::{ParseError, SchemaError};
use super::scan::{RawInstance, Scanned};
use super::string::StepString;

/// Own (non-inherited) explicit attributes of the entity data types read here, in EXPRESS
/// order (ISO 10303-41, -42, -43).
pub const OWN_ATTRIBUTES: &[(&str, &[&str])] = &[
    ("REPRESENTATION_ITEM", &["name"]),
    ("GEOMETRIC_REPRESENTATION_ITEM", &[]),
    ("POINT", &[]),
    ("CARTESIAN_POINT", &["coordinates"]),
    ("CURVE", &[]),
    ("BOUNDED_CURVE", &[]),
    (
        "B_SPLINE_CURVE",
        &[
            "degree",
            "control_points_list",
            "curve_form",
            "closed_curve",
            "self_intersect",
        ],
    ),
    (
        "B_SPLINE_CURVE_WITH_KNOTS",
        &["knot_multiplicities", "knots", "knot_spec"],
    ),
    ("BEZIER_CURVE", &[]),
    ("UNIFORM_CURVE", &[]),
    ("QUASI_UNIFORM_CURVE", &[]),
    ("RATIONAL_B_SPLINE_CURVE", &["weights_data"]),
    ("SURFACE", &[]),
    ("BOUNDED_SURFACE", &[]),
    (
        "B_SPLINE_SURFACE",
        &[
            "u_degree",
            "v_degree",
            "control_points_list",
            "surface_form",
            "u_closed",
            "v_closed",
            "self_intersect",
        ],
    ),
    (
        "B_SPLINE_SURFACE_WITH_KNOTS",
        &[
            "u_multiplicities",
            "v_multiplicities",
            "u_knots",
            "v_knots",
            "knot_spec",
        ],
    ),
    ("BEZIER_SURFACE", &[]),
    ("UNIFORM_SURFACE", &[]),
    ("QUASI_UNIFORM_SURFACE", &[]),
    ("RATIONAL_B_SPLINE_SURFACE", &["weights_data"]),
    ("NAMED_UNIT", &["dimensions"]),
    ("SI_UNIT", &["prefix", "name"]),
    ("LENGTH_UNIT", &[]),
    ("PLANE_ANGLE_UNIT", &[]),
    ("SOLID_ANGLE_UNIT", &[]),
    ("CONVERSION_BASED_UNIT", &["name", "conversion_factor"]),
    ("MEASURE_WITH_UNIT", &["value_component", "unit_component"]),
    ("LENGTH_MEASURE_WITH_UNIT", &[]),
    ("PLANE_ANGLE_MEASURE_WITH_UNIT", &[]),
    ("UNCERTAINTY_MEASURE_WITH_UNIT", &["name", "description"]),
    (
        "REPRESENTATION_CONTEXT",
        &["context_identifier", "context_type"],
    ),
    (
        "GEOMETRIC_REPRESENTATION_CONTEXT",
        &["coordinate_space_dimension"],
    ),
    ("GLOBAL_UNIT_ASSIGNED_CONTEXT", &["units"]),
    ("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT", &["uncertainty"]),
    // ISO 10303-42 clause 4 (geometry): placements, directions and vectors.
    ("PLACEMENT", &["location"]),
    ("DIRECTION", &["direction_ratios"]),
    ("VECTOR", &["orientation", "magnitude"]),
    ("AXIS1_PLACEMENT", &["axis"]),
    ("AXIS2_PLACEMENT_2D", &["ref_direction"]),
    ("AXIS2_PLACEMENT_3D", &["axis", "ref_direction"]),
    // ISO 10303-42 4.4.6-4.4.20: curves.
    ("LINE", &["pnt", "dir"]),
    ("CONIC", &["position"]),
    ("CIRCLE", &["radius"]),
    ("ELLIPSE", &["semi_axis_1", "semi_axis_2"]),
    ("PARABOLA", &["focal_dist"]),
    ("HYPERBOLA", &["semi_axis", "semi_imag_axis"]),
    ("POLYLINE", &["points"]),
    (
        "TRIMMED_CURVE",
        &[
            "basis_curve",
            "trim_1",
            "trim_2",
            "sense_agreement",
            "master_representation",
        ],
    ),
    ("COMPOSITE_CURVE", &["segments", "self_intersect"]),
    ("FOUNDED_ITEM", &[]),
    (
        "COMPOSITE_CURVE_SEGMENT",
        &["transition", "same_sense", "parent_curve"],
    ),
    (
        "SURFACE_CURVE",
        &["curve_3d", "associated_geometry", "master_representation"],
    ),
    ("SEAM_CURVE", &[]),
    ("INTERSECTION_CURVE", &[]),
    ("PCURVE", &["basis_surface", "reference_to_curve"]),
    (
        "OFFSET_CURVE_2D",
        &["basis_curve", "distance", "self_intersect"],
    ),
    (
        "OFFSET_CURVE_3D",
        &["basis_curve", "distance", "self_intersect", "ref_direction"],
    ),
    // ISO 10303-43 representation (for the parameter-space curves of a PCURVE).
    ("REPRESENTATION", &["name", "items", "context_of_items"]),
    ("DEFINITIONAL_REPRESENTATION", &[]),
    // ISO 10303-42 4.4.30-4.4.57: surfaces.
    ("ELEMENTARY_SURFACE", &["position"]),
    ("PLANE", &[]),
    ("CYLINDRICAL_SURFACE", &["radius"]),
    ("CONICAL_SURFACE", &["radius", "semi_angle"]),
    ("SPHERICAL_SURFACE", &["radius"]),
    ("TOROIDAL_SURFACE", &["major_radius", "minor_radius"]),
    ("DEGENERATE_TOROIDAL_SURFACE", &["select_outer"]),
    ("SWEPT_SURFACE", &["swept_curve"]),
    ("SURFACE_OF_LINEAR_EXTRUSION", &["extrusion_axis"]),
    ("SURFACE_OF_REVOLUTION", &["axis_position"]),
    (
        "RECTANGULAR_TRIMMED_SURFACE",
        &["basis_surface", "u1", "u2", "v1", "v2", "usense", "vsense"],
    ),
    (
        "OFFSET_SURFACE",
        &["basis_surface", "distance", "self_intersect"],
    ),
    // ISO 10303-42 clause 5 (topology): what bounds an edge curve or a face surface.
    ("TOPOLOGICAL_REPRESENTATION_ITEM", &[]),
    ("VERTEX", &[]),
    ("VERTEX_POINT", &["vertex_geometry"]),
    ("EDGE", &["edge_start", "edge_end"]),
    ("EDGE_CURVE", &["edge_geometry", "same_sense"]),
    ("ORIENTED_EDGE", &["edge_element", "orientation"]),
    ("LOOP", &[]),
    ("PATH", &["edge_list"]),
    ("EDGE_LOOP", &[]),
    ("FACE_BOUND", &["bound", "orientation"]),
    ("FACE_OUTER_BOUND", &[]),
    ("FACE", &["bounds"]),
    ("FACE_SURFACE", &["face_geometry", "same_sense"]),
    ("ADVANCED_FACE", &[]),
    ("ORIENTED_FACE", &["face_element", "orientation"]),
    ("VERTEX_LOOP", &["loop_vertex"]),
    ("POLY_LOOP", &["polygon"]),
    ("CONNECTED_FACE_SET", &["cfs_faces"]),
    ("OPEN_SHELL", &[]),
    ("CLOSED_SHELL", &[]),
    (
        "ORIENTED_CLOSED_SHELL",
        &["closed_shell_element", "orientation"],
    ),
    // ISO 10303-42 clause 6 (geometric models): solids, surface models and sets.
    ("SOLID_MODEL", &[]),
    ("MANIFOLD_SOLID_BREP", &["outer"]),
    ("BREP_WITH_VOIDS", &["voids"]),
    ("SHELL_BASED_SURFACE_MODEL", &["sbsm_boundary"]),
    ("FACE_BASED_SURFACE_MODEL", &["fbsm_faces"]),
    ("GEOMETRIC_SET", &["elements"]),
    ("GEOMETRIC_CURVE_SET", &[]),
    // ISO 10303-41 product structure and ISO 10303-43 representation structure (the
    // assembly: which product definition uses which, and where its shape goes).
    (
        "PRODUCT",
        &["id", "name", "description", "frame_of_reference"],
    ),
    (
        "PRODUCT_DEFINITION_FORMATION",
        &["id", "description", "of_product"],
    ),
    (
        "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE",
        &["make_or_buy"],
    ),
    (
        "PRODUCT_DEFINITION",
        &["id", "description", "formation", "frame_of_reference"],
    ),
    (
        "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS",
        &["documentation_ids"],
    ),
    (
        "PROPERTY_DEFINITION",
        &["name", "description", "definition"],
    ),
    ("PRODUCT_DEFINITION_SHAPE", &[]),
    (
        "PROPERTY_DEFINITION_REPRESENTATION",
        &["definition", "used_representation"],
    ),
    ("SHAPE_DEFINITION_REPRESENTATION", &[]),
    (
        "PRODUCT_DEFINITION_RELATIONSHIP",
        &[
            "id",
            "name",
            "description",
            "relating_product_definition",
            "related_product_definition",
        ],
    ),
    ("PRODUCT_DEFINITION_USAGE", &[]),
    ("ASSEMBLY_COMPONENT_USAGE", &["reference_designator"]),
    ("NEXT_ASSEMBLY_USAGE_OCCURRENCE", &[]),
    (
        "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
        &["representation_relation", "represented_product_relation"],
    ),
    (
        "REPRESENTATION_RELATIONSHIP",
        &["name", "description", "rep_1", "rep_2"],
    ),
    (
        "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
        &["transformation_operator"],
    ),
    ("SHAPE_REPRESENTATION_RELATIONSHIP", &[]),
    (
        "ITEM_DEFINED_TRANSFORMATION",
        &[
            "name",
            "description",
            "transform_item_1",
            "transform_item_2",
        ],
    ),
    ("SHAPE_REPRESENTATION", &[]),
    ("ADVANCED_BREP_SHAPE_REPRESENTATION", &[]),
    ("FACETED_BREP_SHAPE_REPRESENTATION", &[]),
    ("MANIFOLD_SURFACE_SHAPE_REPRESENTATION", &[]),
    ("GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION", &[]),
    ("GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION", &[]),
    ("EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION", &[]),
    ("MAPPED_ITEM", &["mapping_source", "mapping_target"]),
    (
        "REPRESENTATION_MAP",
        &["mapping_origin", "mapped_representation"],
    ),
];

const CURVE_CHAIN: [&str; 5] = [
    "REPRESENTATION_ITEM",
    "GEOMETRIC_REPRESENTATION_ITEM",
    "CURVE",
    "BOUNDED_CURVE",
    "B_SPLINE_CURVE",
];
const SURFACE_CHAIN: [&str; 5] = [
    "REPRESENTATION_ITEM",
    "GEOMETRIC_REPRESENTATION_ITEM",
    "SURFACE",
    "BOUNDED_SURFACE",
    "B_SPLINE_SURFACE",
];

const RI: &str = "REPRESENTATION_ITEM";
const GRI: &str = "GEOMETRIC_REPRESENTATION_ITEM";
const TRI: &str = "TOPOLOGICAL_REPRESENTATION_ITEM";

/// The supertype chain (root first) of each entity that can appear as a simple instance;
/// a simple instance's parameters are the own attributes of each, in this order.
pub const SUPERTYPE_CHAINS: &[(&str, &[&str])] = &[
    // ISO 10303-42 geometry (clause 4) and topology (clause 5): the chains of the
    // EXPRESS SUBTYPE OF clauses, root first.
    ("DIRECTION", &[RI, GRI, "DIRECTION"]),
    ("VECTOR", &[RI, GRI, "VECTOR"]),
    (
        "AXIS1_PLACEMENT",
        &[RI, GRI, "PLACEMENT", "AXIS1_PLACEMENT"],
    ),
    (
        "AXIS2_PLACEMENT_2D",
        &[RI, GRI, "PLACEMENT", "AXIS2_PLACEMENT_2D"],
    ),
    (
        "AXIS2_PLACEMENT_3D",
        &[RI, GRI, "PLACEMENT", "AXIS2_PLACEMENT_3D"],
    ),
    ("LINE", &[RI, GRI, "CURVE", "LINE"]),
    ("CIRCLE", &[RI, GRI, "CURVE", "CONIC", "CIRCLE"]),
    ("ELLIPSE", &[RI, GRI, "CURVE", "CONIC", "ELLIPSE"]),
    ("PARABOLA", &[RI, GRI, "CURVE", "CONIC", "PARABOLA"]),
    ("HYPERBOLA", &[RI, GRI, "CURVE", "CONIC", "HYPERBOLA"]),
    ("POLYLINE", &[RI, GRI, "CURVE", "BOUNDED_CURVE", "POLYLINE"]),
    (
        "TRIMMED_CURVE",
        &[RI, GRI, "CURVE", "BOUNDED_CURVE", "TRIMMED_CURVE"],
    ),
    (
        "COMPOSITE_CURVE",
        &[RI, GRI, "CURVE", "BOUNDED_CURVE", "COMPOSITE_CURVE"],
    ),
    (
        "COMPOSITE_CURVE_SEGMENT",
        &["FOUNDED_ITEM", "COMPOSITE_CURVE_SEGMENT"],
    ),
    ("SURFACE_CURVE", &[RI, GRI, "CURVE", "SURFACE_CURVE"]),
    (
        "SEAM_CURVE",
        &[RI, GRI, "CURVE", "SURFACE_CURVE", "SEAM_CURVE"],
    ),
    (
        "INTERSECTION_CURVE",
        &[RI, GRI, "CURVE", "SURFACE_CURVE", "INTERSECTION_CURVE"],
    ),
    ("PCURVE", &[RI, GRI, "CURVE", "PCURVE"]),
    ("OFFSET_CURVE_2D", &[RI, GRI, "CURVE", "OFFSET_CURVE_2D"]),
    ("OFFSET_CURVE_3D", &[RI, GRI, "CURVE", "OFFSET_CURVE_3D"]),
    (
        "DEFINITIONAL_REPRESENTATION",
        &["REPRESENTATION", "DEFINITIONAL_REPRESENTATION"],
    ),
    (
        "PLANE",
        &[RI, GRI, "SURFACE", "ELEMENTARY_SURFACE", "PLANE"],
    ),
    (
        "CYLINDRICAL_SURFACE",
        &[
            RI,
            GRI,
            "SURFACE",
            "ELEMENTARY_SURFACE",
            "CYLINDRICAL_SURFACE",
        ],
    ),
    (
        "CONICAL_SURFACE",
        &[RI, GRI, "SURFACE", "ELEMENTARY_SURFACE", "CONICAL_SURFACE"],
    ),
    (
        "SPHERICAL_SURFACE",
        &[
            RI,
            GRI,
            "SURFACE",
            "ELEMENTARY_SURFACE",
            "SPHERICAL_SURFACE",
        ],
    ),
    (
        "TOROIDAL_SURFACE",
        &[RI, GRI, "SURFACE", "ELEMENTARY_SURFACE", "TOROIDAL_SURFACE"],
    ),
    (
        "DEGENERATE_TOROIDAL_SURFACE",
        &[
            RI,
            GRI,
            "SURFACE",
            "ELEMENTARY_SURFACE",
            "TOROIDAL_SURFACE",
            "DEGENERATE_TOROIDAL_SURFACE",
        ],
    ),
    (
        "SURFACE_OF_LINEAR_EXTRUSION",
        &[
            RI,
            GRI,
            "SURFACE",
            "SWEPT_SURFACE",
            "SURFACE_OF_LINEAR_EXTRUSION",
        ],
    ),
    (
        "SURFACE_OF_REVOLUTION",
        &[RI, GRI, "SURFACE", "SWEPT_SURFACE", "SURFACE_OF_REVOLUTION"],
    ),
    (
        "RECTANGULAR_TRIMMED_SURFACE",
        &[
            RI,
            GRI,
            "SURFACE",
            "BOUNDED_SURFACE",
            "RECTANGULAR_TRIMMED_SURFACE",
        ],
    ),
    ("OFFSET_SURFACE", &[RI, GRI, "SURFACE", "OFFSET_SURFACE"]),
    ("VERTEX_POINT", &[RI, TRI, "VERTEX", "VERTEX_POINT"]),
    ("EDGE_CURVE", &[RI, TRI, "EDGE", "EDGE_CURVE"]),
    ("ORIENTED_EDGE", &[RI, TRI, "EDGE", "ORIENTED_EDGE"]),
    ("EDGE_LOOP", &[RI, TRI, "LOOP", "PATH", "EDGE_LOOP"]),
    ("FACE_BOUND", &[RI, TRI, "FACE_BOUND"]),
    (
        "FACE_OUTER_BOUND",
        &[RI, TRI, "FACE_BOUND", "FACE_OUTER_BOUND"],
    ),
    ("FACE_SURFACE", &[RI, TRI, "FACE", "FACE_SURFACE"]),
    (
        "ADVANCED_FACE",
        &[RI, TRI, "FACE", "FACE_SURFACE", "ADVANCED_FACE"],
    ),
    ("ORIENTED_FACE", &[RI, TRI, "FACE", "ORIENTED_FACE"]),
    ("VERTEX_LOOP", &[RI, TRI, "LOOP", "VERTEX_LOOP"]),
    ("POLY_LOOP", &[RI, GRI, TRI, "LOOP", "POLY_LOOP"]),
    ("CONNECTED_FACE_SET", &[RI, TRI, "CONNECTED_FACE_SET"]),
    ("OPEN_SHELL", &[RI, TRI, "CONNECTED_FACE_SET", "OPEN_SHELL"]),
    (
        "CLOSED_SHELL",
        &[RI, TRI, "CONNECTED_FACE_SET", "CLOSED_SHELL"],
    ),
    (
        "ORIENTED_CLOSED_SHELL",
        &[
            RI,
            TRI,
            "CONNECTED_FACE_SET",
            "CLOSED_SHELL",
            "ORIENTED_CLOSED_SHELL",
        ],
    ),
    (
        "MANIFOLD_SOLID_BREP",
        &[RI, GRI, "SOLID_MODEL", "MANIFOLD_SOLID_BREP"],
    ),
    (
        "BREP_WITH_VOIDS",
        &[
            RI,
            GRI,
            "SOLID_MODEL",
            "MANIFOLD_SOLID_BREP",
            "BREP_WITH_VOIDS",
        ],
    ),
    (
        "SHELL_BASED_SURFACE_MODEL",
        &[RI, GRI, "SHELL_BASED_SURFACE_MODEL"],
    ),
    (
        "FACE_BASED_SURFACE_MODEL",
        &[RI, GRI, "FACE_BASED_SURFACE_MODEL"],
    ),
    ("GEOMETRIC_SET", &[RI, GRI, "GEOMETRIC_SET"]),
    (
        "GEOMETRIC_CURVE_SET",
        &[RI, GRI, "GEOMETRIC_SET", "GEOMETRIC_CURVE_SET"],
    ),
    (
        "CARTESIAN_POINT",
        &[
            "REPRESENTATION_ITEM",
            "GEOMETRIC_REPRESENTATION_ITEM",
            "POINT",
            "CARTESIAN_POINT",
        ],
    ),
    ("B_SPLINE_CURVE", &CURVE_CHAIN),
    (
        "B_SPLINE_CURVE_WITH_KNOTS",
        &[
            CURVE_CHAIN[0],
            CURVE_CHAIN[1],
            CURVE_CHAIN[2],
            CURVE_CHAIN[3],
            CURVE_CHAIN[4],
            "B_SPLINE_CURVE_WITH_KNOTS",
        ],
    ),
    (
        "BEZIER_CURVE",
        &[
            CURVE_CHAIN[0],
            CURVE_CHAIN[1],
            CURVE_CHAIN[2],
            CURVE_CHAIN[3],
            CURVE_CHAIN[4],
            "BEZIER_CURVE",
        ],
    ),
    (
        "UNIFORM_CURVE",
        &[
            CURVE_CHAIN[0],
            CURVE_CHAIN[1],
            CURVE_CHAIN[2],
            CURVE_CHAIN[3],
            CURVE_CHAIN[4],
            "UNIFORM_CURVE",
        ],
    ),
    (
        "QUASI_UNIFORM_CURVE",
        &[
            CURVE_CHAIN[0],
            CURVE_CHAIN[1],
            CURVE_CHAIN[2],
            CURVE_CHAIN[3],
            CURVE_CHAIN[4],
            "QUASI_UNIFORM_CURVE",
        ],
    ),
    ("B_SPLINE_SURFACE", &SURFACE_CHAIN),
    (
        "B_SPLINE_SURFACE_WITH_KNOTS",
        &[
            SURFACE_CHAIN[0],
            SURFACE_CHAIN[1],
            SURFACE_CHAIN[2],
            SURFACE_CHAIN[3],
            SURFACE_CHAIN[4],
            "B_SPLINE_SURFACE_WITH_KNOTS",
        ],
    ),
    (
        "BEZIER_SURFACE",
        &[
            SURFACE_CHAIN[0],
            SURFACE_CHAIN[1],
            SURFACE_CHAIN[2],
            SURFACE_CHAIN[3],
            SURFACE_CHAIN[4],
            "BEZIER_SURFACE",
        ],
    ),
    (
        "UNIFORM_SURFACE",
        &[
            SURFACE_CHAIN[0],
            SURFACE_CHAIN[1],
            SURFACE_CHAIN[2],
            SURFACE_CHAIN[3],
            SURFACE_CHAIN[4],
            "UNIFORM_SURFACE",
        ],
    ),
    (
        "QUASI_UNIFORM_SURFACE",
        &[
            SURFACE_CHAIN[0],
            SURFACE_CHAIN[1],
            SURFACE_CHAIN[2],
            SURFACE_CHAIN[3],
            SURFACE_CHAIN[4],
            "QUASI_UNIFORM_SURFACE",
        ],
    ),
    ("SI_UNIT", &["NAMED_UNIT", "SI_UNIT"]),
    (
        "CONVERSION_BASED_UNIT",
        &["NAMED_UNIT", "CONVERSION_BASED_UNIT"],
    ),
    ("MEASURE_WITH_UNIT", &["MEASURE_WITH_UNIT"]),
    (
        "LENGTH_MEASURE_WITH_UNIT",
        &["MEASURE_WITH_UNIT", "LENGTH_MEASURE_WITH_UNIT"],
    ),
    (
        "UNCERTAINTY_MEASURE_WITH_UNIT",
        &["MEASURE_WITH_UNIT", "UNCERTAINTY_MEASURE_WITH_UNIT"],
    ),
    (
        "PLANE_ANGLE_MEASURE_WITH_UNIT",
        &["MEASURE_WITH_UNIT", "PLANE_ANGLE_MEASURE_WITH_UNIT"],
    ),
    // ISO 10303-41 / -43 product and representation structure (the EXPRESS SUBTYPE OF
    // chains, root first).
    ("PRODUCT", &["PRODUCT"]),
    (
        "PRODUCT_DEFINITION_FORMATION",
        &["PRODUCT_DEFINITION_FORMATION"],
    ),
    (
        "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE",
        &[
            "PRODUCT_DEFINITION_FORMATION",
            "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE",
        ],
    ),
    ("PRODUCT_DEFINITION", &["PRODUCT_DEFINITION"]),
    (
        "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS",
        &[
            "PRODUCT_DEFINITION",
            "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS",
        ],
    ),
    (
        "PRODUCT_DEFINITION_SHAPE",
        &["PROPERTY_DEFINITION", "PRODUCT_DEFINITION_SHAPE"],
    ),
    (
        "SHAPE_DEFINITION_REPRESENTATION",
        &[
            "PROPERTY_DEFINITION_REPRESENTATION",
            "SHAPE_DEFINITION_REPRESENTATION",
        ],
    ),
    (
        "NEXT_ASSEMBLY_USAGE_OCCURRENCE",
        &[
            "PRODUCT_DEFINITION_RELATIONSHIP",
            "PRODUCT_DEFINITION_USAGE",
            "ASSEMBLY_COMPONENT_USAGE",
            "NEXT_ASSEMBLY_USAGE_OCCURRENCE",
        ],
    ),
    (
        "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
        &["CONTEXT_DEPENDENT_SHAPE_REPRESENTATION"],
    ),
    (
        "REPRESENTATION_RELATIONSHIP",
        &["REPRESENTATION_RELATIONSHIP"],
    ),
    (
        "SHAPE_REPRESENTATION_RELATIONSHIP",
        &[
            "REPRESENTATION_RELATIONSHIP",
            "SHAPE_REPRESENTATION_RELATIONSHIP",
        ],
    ),
    (
        "ITEM_DEFINED_TRANSFORMATION",
        &["ITEM_DEFINED_TRANSFORMATION"],
    ),
    (
        "SHAPE_REPRESENTATION",
        &["REPRESENTATION", "SHAPE_REPRESENTATION"],
    ),
    (
        "ADVANCED_BREP_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "ADVANCED_BREP_SHAPE_REPRESENTATION",
        ],
    ),
    (
        "FACETED_BREP_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "FACETED_BREP_SHAPE_REPRESENTATION",
        ],
    ),
    (
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
        ],
    ),
    (
        "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
        ],
    ),
    (
        "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
        ],
    ),
    (
        "EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION",
        &[
            "REPRESENTATION",
            "SHAPE_REPRESENTATION",
            "EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION",
        ],
    ),
    ("MAPPED_ITEM", &[RI, "MAPPED_ITEM"]),
    ("REPRESENTATION_MAP", &["REPRESENTATION_MAP"]),
    ("REPRESENTATION_CONTEXT", &["REPRESENTATION_CONTEXT"]),
    (
        "GEOMETRIC_REPRESENTATION_CONTEXT",
        &["REPRESENTATION_CONTEXT", "GEOMETRIC_REPRESENTATION_CONTEXT"],
    ),
];

/// The entity types a reference attribute may name, transcribed from the attribute's
/// EXPRESS type (ISO 10303-41, -42, -43; a SELECT type lists its members, an entity type
/// admits its subtypes): `(entity declaring it, attribute, allowed types)`. Every
/// reference inside the attribute's value (a list's elements too) is checked against it by
/// [`Scanned::reference_type_errors`], for simple and complex instances alike. B-spline
/// control points are checked where they are read (a pole that is not a CARTESIAN_POINT
/// stops the curve from loading).
pub const REFERENCE_TYPES: &[(&str, &str, &[&str])] = &[
    // ISO 10303-42 clause 4: geometry.
    ("PLACEMENT", "location", &["CARTESIAN_POINT"]),
    ("VECTOR", "orientation", &["DIRECTION"]),
    ("AXIS1_PLACEMENT", "axis", &["DIRECTION"]),
    ("AXIS2_PLACEMENT_2D", "ref_direction", &["DIRECTION"]),
    ("AXIS2_PLACEMENT_3D", "axis", &["DIRECTION"]),
    ("AXIS2_PLACEMENT_3D", "ref_direction", &["DIRECTION"]),
    ("LINE", "pnt", &["CARTESIAN_POINT"]),
    ("LINE", "dir", &["VECTOR"]),
    // axis2_placement = SELECT (axis2_placement_2d, axis2_placement_3d)
    (
        "CONIC",
        "position",
        &["AXIS2_PLACEMENT_2D", "AXIS2_PLACEMENT_3D"],
    ),
    ("POLYLINE", "points", &["CARTESIAN_POINT"]),
    ("TRIMMED_CURVE", "basis_curve", &["CURVE"]),
    // trimming_select = SELECT (cartesian_point, parameter_value): the references.
    ("TRIMMED_CURVE", "trim_1", &["CARTESIAN_POINT"]),
    ("TRIMMED_CURVE", "trim_2", &["CARTESIAN_POINT"]),
    ("COMPOSITE_CURVE", "segments", &["COMPOSITE_CURVE_SEGMENT"]),
    ("COMPOSITE_CURVE_SEGMENT", "parent_curve", &["CURVE"]),
    ("SURFACE_CURVE", "curve_3d", &["CURVE"]),
    // pcurve_or_surface = SELECT (pcurve, surface)
    (
        "SURFACE_CURVE",
        "associated_geometry",
        &["PCURVE", "SURFACE"],
    ),
    ("PCURVE", "basis_surface", &["SURFACE"]),
    (
        "PCURVE",
        "reference_to_curve",
        &["DEFINITIONAL_REPRESENTATION"],
    ),
    ("OFFSET_CURVE_2D", "basis_curve", &["CURVE"]),
    ("OFFSET_CURVE_3D", "basis_curve", &["CURVE"]),
    ("OFFSET_CURVE_3D", "ref_direction", &["DIRECTION"]),
    ("ELEMENTARY_SURFACE", "position", &["AXIS2_PLACEMENT_3D"]),
    ("SWEPT_SURFACE", "swept_curve", &["CURVE"]),
    ("SURFACE_OF_LINEAR_EXTRUSION", "extrusion_axis", &["VECTOR"]),
    (
        "SURFACE_OF_REVOLUTION",
        "axis_position",
        &["AXIS1_PLACEMENT"],
    ),
    ("RECTANGULAR_TRIMMED_SURFACE", "basis_surface", &["SURFACE"]),
    ("OFFSET_SURFACE", "basis_surface", &["SURFACE"]),
    // ISO 10303-42 clause 5: topology.
    ("VERTEX_POINT", "vertex_geometry", &["POINT"]),
    ("EDGE", "edge_start", &["VERTEX"]),
    ("EDGE", "edge_end", &["VERTEX"]),
    ("EDGE_CURVE", "edge_geometry", &["CURVE"]),
    ("ORIENTED_EDGE", "edge_element", &["EDGE"]),
    ("PATH", "edge_list", &["ORIENTED_EDGE"]),
    ("FACE_BOUND", "bound", &["LOOP"]),
    ("FACE", "bounds", &["FACE_BOUND"]),
    ("FACE_SURFACE", "face_geometry", &["SURFACE"]),
    ("ORIENTED_FACE", "face_element", &["FACE"]),
    ("VERTEX_LOOP", "loop_vertex", &["VERTEX"]),
    ("POLY_LOOP", "polygon", &["CARTESIAN_POINT"]),
    ("CONNECTED_FACE_SET", "cfs_faces", &["FACE"]),
    (
        "ORIENTED_CLOSED_SHELL",
        "closed_shell_element",
        &["CLOSED_SHELL"],
    ),
    // ISO 10303-42 clause 6: geometric models.
    ("MANIFOLD_SOLID_BREP", "outer", &["CLOSED_SHELL"]),
    ("BREP_WITH_VOIDS", "voids", &["ORIENTED_CLOSED_SHELL"]),
    // shell = SELECT (vertex_shell, wire_shell, open_shell, closed_shell)
    (
        "SHELL_BASED_SURFACE_MODEL",
        "sbsm_boundary",
        &["VERTEX_SHELL", "WIRE_SHELL", "OPEN_SHELL", "CLOSED_SHELL"],
    ),
    (
        "FACE_BASED_SURFACE_MODEL",
        "fbsm_faces",
        &["CONNECTED_FACE_SET"],
    ),
    // geometric_set_select = SELECT (point, curve, surface)
    ("GEOMETRIC_SET", "elements", &["POINT", "CURVE", "SURFACE"]),
    // ISO 10303-41 units and ISO 10303-43 contexts; unit = SELECT (named_unit,
    // derived_unit).
    ("NAMED_UNIT", "dimensions", &["DIMENSIONAL_EXPONENTS"]),
    (
        "CONVERSION_BASED_UNIT",
        "conversion_factor",
        &["MEASURE_WITH_UNIT"],
    ),
    (
        "MEASURE_WITH_UNIT",
        "unit_component",
        &["NAMED_UNIT", "DERIVED_UNIT"],
    ),
    (
        "GLOBAL_UNIT_ASSIGNED_CONTEXT",
        "units",
        &["NAMED_UNIT", "DERIVED_UNIT"],
    ),
    (
        "GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT",
        "uncertainty",
        &["UNCERTAINTY_MEASURE_WITH_UNIT"],
    ),
    // ISO 10303-43 representations.
    ("REPRESENTATION", "items", &["REPRESENTATION_ITEM"]),
    (
        "REPRESENTATION",
        "context_of_items",
        &["REPRESENTATION_CONTEXT"],
    ),
    // representation_or_representation_reference (ISO 10303-43 edition 3)
    (
        "REPRESENTATION_RELATIONSHIP",
        "rep_1",
        &["REPRESENTATION", "REPRESENTATION_REFERENCE"],
    ),
    (
        "REPRESENTATION_RELATIONSHIP",
        "rep_2",
        &["REPRESENTATION", "REPRESENTATION_REFERENCE"],
    ),
    // transformation = SELECT (item_defined_transformation, functionally_defined_transformation)
    (
        "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
        "transformation_operator",
        &[
            "ITEM_DEFINED_TRANSFORMATION",
            "FUNCTIONALLY_DEFINED_TRANSFORMATION",
        ],
    ),
    (
        "ITEM_DEFINED_TRANSFORMATION",
        "transform_item_1",
        &["REPRESENTATION_ITEM"],
    ),
    (
        "ITEM_DEFINED_TRANSFORMATION",
        "transform_item_2",
        &["REPRESENTATION_ITEM"],
    ),
    ("MAPPED_ITEM", "mapping_source", &["REPRESENTATION_MAP"]),
    ("MAPPED_ITEM", "mapping_target", &["REPRESENTATION_ITEM"]),
    (
        "REPRESENTATION_MAP",
        "mapping_origin",
        &["REPRESENTATION_ITEM"],
    ),
    (
        "REPRESENTATION_MAP",
        "mapped_representation",
        &["REPRESENTATION"],
    ),
    // ISO 10303-41 product structure.
    ("PRODUCT", "frame_of_reference", &["PRODUCT_CONTEXT"]),
    ("PRODUCT_DEFINITION_FORMATION", "of_product", &["PRODUCT"]),
    (
        "PRODUCT_DEFINITION",
        "formation",
        &["PRODUCT_DEFINITION_FORMATION"],
    ),
    (
        "PRODUCT_DEFINITION",
        "frame_of_reference",
        &["PRODUCT_DEFINITION_CONTEXT"],
    ),
    // product_definition_or_reference (ISO 10303-41 edition 3)
    (
        "PRODUCT_DEFINITION_RELATIONSHIP",
        "relating_product_definition",
        &["PRODUCT_DEFINITION", "PRODUCT_DEFINITION_REFERENCE"],
    ),
    (
        "PRODUCT_DEFINITION_RELATIONSHIP",
        "related_product_definition",
        &["PRODUCT_DEFINITION", "PRODUCT_DEFINITION_REFERENCE"],
    ),
    // represented_definition = SELECT (general_property, property_definition,
    // property_definition_relationship, shape_aspect, shape_aspect_relationship)
    (
        "PROPERTY_DEFINITION_REPRESENTATION",
        "definition",
        &[
            "GENERAL_PROPERTY",
            "PROPERTY_DEFINITION",
            "PROPERTY_DEFINITION_RELATIONSHIP",
            "SHAPE_ASPECT",
            "SHAPE_ASPECT_RELATIONSHIP",
        ],
    ),
    (
        "PROPERTY_DEFINITION_REPRESENTATION",
        "used_representation",
        &["REPRESENTATION"],
    ),
    (
        "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
        "representation_relation",
        &["SHAPE_REPRESENTATION_RELATIONSHIP"],
    ),
    (
        "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
        "represented_product_relation",
        &["PRODUCT_DEFINITION_SHAPE"],
    ),
];

/// Short names (ISO 10303-21 clause 12.2.4 allows them) confirmed in Open CASCADE's
/// readers (`NamedForComplex(long, short)` in RWStepGeom) and the spec (c.4).
const SHORT_NAMES: &[(&str, &str)] = &[
    ("CRTPNT", "CARTESIAN_POINT"),
    ("BNDCRV", "BOUNDED_CURVE"),
    ("BSPCR", "B_SPLINE_CURVE"),
    ("BSCWK", "B_SPLINE_CURVE_WITH_KNOTS"),
    ("BSSWK", "B_SPLINE_SURFACE_WITH_KNOTS"),
    ("RBSC", "RATIONAL_B_SPLINE_CURVE"),
    ("GMRPIT", "GEOMETRIC_REPRESENTATION_ITEM"),
    ("RPRITM", "REPRESENTATION_ITEM"),
];

// `canonical_name` relies on every short name having at most 6 characters.
const _: () = {
    let mut i = 0;
    while i < SHORT_NAMES.len() {
        assert!(SHORT_NAMES[i].0.len() <= 6);
        i += 1;
    }
};

/// The long entity name for a keyword (short names mapped; anything else unchanged).
pub fn canonical_name(keyword: &str) -> &str {
    // Short names have at most 6 characters (ISO 10303-21 annex; the list above); every
    // instance of a large file goes through here, so skip the table for long keywords.
    if keyword.len() > 6 {
        return keyword;
    }
    SHORT_NAMES
        .iter()
        .find(|(s, _)| *s == keyword)
        .map_or(keyword, |(_, l)| l)
}

/// A complex instance read as one entity (a B-spline, a point) whose partial records
/// include one the schema tables do not know *with parameters*: its values would be
/// dropped unread (a misspelt `RATIONAL_B_SPLINE_CURVE` would turn a rational curve into a
/// polynomial one), so the instance has no unambiguous meaning and is refused. Unknown
/// partials without parameters carry nothing and are ignored.
fn refuse_unknown_data(inst: &Instance<'_>, a: &Attributes<'_, '_>) -> Result<(), SchemaError> {
    if let Body::Complex(records) = &inst.body {
        if let Some(r) = records
            .iter()
            .find(|r| !r.params.is_empty() && own_attributes(canonical_name(r.keyword)).is_none())
        {
            return Err(a.error(format!(
                "partial entity {} carries parameters but is not an entity data type of {}; its values cannot be placed, the instance is not read",
                r.keyword,
                a.entity_type()
            )));
        }
    }
    Ok(())
}

fn own_attributes(entity: &str) -> Option<&'static [&'static str]> {
    OWN_ATTRIBUTES
        .iter()
        .find(|(e, _)| *e == entity)
        .map(|(_, a)| *a)
}

/// Where an instance is, for error messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct At {
    /// The instance id.
    pub id: u64,
    /// 1-based line of the instance.
    pub line: usize,
    /// 1-based column of the instance.
    pub column: usize,
}

/// One attribute found in an instance.
#[derive(Debug, Clone, Copy)]
struct Slot<'i, 'a> {
    name: &'static str,
    entity: &'static str,
    position: usize,
    value: &'i Parameter<'a>,
}

/// The attributes of an instance, by EXPRESS name, whatever the instance's shape.
#[derive(Debug)]
pub struct Attributes<'i, 'a> {
    at: At,
    entity_type: String,
    partials: Vec<&'static str>,
    slots: Vec<Slot<'i, 'a>>,
}

impl<'i, 'a> Attributes<'i, 'a> {
    /// Maps an instance's parameters to attribute names. A simple instance must be one of
    /// [`SUPERTYPE_CHAINS`] with exactly the chain's attribute count; in a complex instance
    /// each known partial must have its own attribute count, and unknown partials are
    /// ignored (listed in [`Attributes::entity_type`]).
    pub fn of(inst: &'i Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let mut partials = Vec::new();
        let mut slots = Vec::new();
        let err = |entity_type: &str, message: String| SchemaError {
            entity: at.id,
            entity_type: entity_type.to_owned(),
            attribute: None,
            message,
            line: at.line,
            column: at.column,
        };
        let entity_type;
        match &inst.body {
            Body::Simple(r) => {
                let name = canonical_name(r.keyword);
                entity_type = name.to_owned();
                let Some((_, chain)) = SUPERTYPE_CHAINS.iter().find(|(e, _)| *e == name) else {
                    return Err(err(name, "not an entity type this reader knows".to_owned()));
                };
                let mut position = 0;
                for &entity in *chain {
                    partials.push(entity);
                    for &attr in own_attributes(entity).unwrap_or_default() {
                        position += 1;
                        if let Some(value) = r.params.get(position - 1) {
                            slots.push(Slot {
                                name: attr,
                                entity,
                                position,
                                value,
                            });
                        }
                    }
                }
                if position != r.params.len() {
                    return Err(err(
                        name,
                        format!("expected {position} parameters, found {}", r.params.len()),
                    ));
                }
            }
            Body::Complex(records) => {
                let names: Vec<&str> = records.iter().map(|r| canonical_name(r.keyword)).collect();
                entity_type = format!("({})", names.join(","));
                for r in records {
                    let name = canonical_name(r.keyword);
                    let Some((entity, attrs)) = OWN_ATTRIBUTES.iter().find(|(e, _)| *e == name)
                    else {
                        continue;
                    };
                    if attrs.len() != r.params.len() {
                        return Err(err(
                            entity,
                            format!(
                                "partial entity {entity} expects {} parameters, found {}",
                                attrs.len(),
                                r.params.len()
                            ),
                        ));
                    }
                    partials.push(*entity);
                    for (i, (&attr, value)) in attrs.iter().zip(&r.params).enumerate() {
                        slots.push(Slot {
                            name: attr,
                            entity,
                            position: i + 1,
                            value,
                        });
                    }
                }
            }
        }
        Ok(Attributes {
            at,
            entity_type,
            partials,
            slots,
        })
    }

    /// The entity type as written: `B_SPLINE_CURVE_WITH_KNOTS`, or
    /// `(BOUNDED_CURVE,B_SPLINE_CURVE,...)` for a complex instance.
    pub fn entity_type(&self) -> &str {
        &self.entity_type
    }

    /// Whether the instance is of (or contains the partial) entity data type `entity`.
    pub fn has(&self, entity: &str) -> bool {
        self.partials.contains(&entity)
    }

    /// A schema error about this instance (no particular attribute).
    pub fn error(&self, message: impl Into<String>) -> SchemaError {
        SchemaError {
            entity: self.at.id,
            entity_type: self.entity_type.clone(),
            attribute: None,
            message: message.into(),
            line: self.at.line,
            column: self.at.column,
        }
    }

    fn slot(&self, entity: &str, name: &'static str) -> Result<Slot<'i, 'a>, SchemaError> {
        self.slots
            .iter()
            .find(|s| s.entity == entity && s.name == name)
            .copied()
            .ok_or_else(|| self.error(format!("attribute `{name}` of {entity} is missing")))
    }

    fn slot_error(&self, s: &Slot<'i, 'a>, message: String) -> SchemaError {
        SchemaError {
            entity: self.at.id,
            entity_type: s.entity.to_owned(),
            attribute: Some((s.position, s.name)),
            message,
            line: self.at.line,
            column: self.at.column,
        }
    }

    /// The raw parameter of attribute `name` declared by `entity`.
    pub fn param(
        &self,
        entity: &str,
        name: &'static str,
    ) -> Result<&'i Parameter<'a>, SchemaError> {
        self.slot(entity, name).map(|s| s.value)
    }

    /// An INTEGER attribute.
    pub fn integer(&self, entity: &str, name: &'static str) -> Result<i64, SchemaError> {
        let s = self.slot(entity, name)?;
        s.value.as_integer().ok_or_else(|| {
            self.slot_error(
                &s,
                format!("expected an integer, found {}", s.value.kind_name()),
            )
        })
    }

    /// An enumeration attribute (value without dots).
    pub fn enumeration(&self, entity: &str, name: &'static str) -> Result<&'a str, SchemaError> {
        let s = self.slot(entity, name)?;
        s.value.as_enumeration().ok_or_else(|| {
            self.slot_error(
                &s,
                format!("expected an enumeration, found {}", s.value.kind_name()),
            )
        })
    }

    /// A LOGICAL attribute (`.T.`, `.F.`, `.U.`).
    pub fn logical(&self, entity: &str, name: &'static str) -> Result<Logical, SchemaError> {
        let s = self.slot(entity, name)?;
        match s.value.as_enumeration() {
            Some("T") => Ok(Logical::True),
            Some("F") => Ok(Logical::False),
            Some("U") => Ok(Logical::Unknown),
            _ => Err(self.slot_error(
                &s,
                format!("expected .T., .F. or .U., found {}", render(s.value)),
            )),
        }
    }

    /// A REAL attribute (an INTEGER accepted as a real; a typed value such as
    /// `PLANE_ANGLE_MEASURE(0.5)` or `POSITIVE_LENGTH_MEASURE(2.)` unwrapped).
    pub fn real(&self, entity: &str, name: &'static str) -> Result<f64, SchemaError> {
        let s = self.slot(entity, name)?;
        let v = match s.value {
            Parameter::Typed(_, inner) => inner.as_real(),
            other => other.as_real(),
        };
        v.ok_or_else(|| self.slot_error(&s, format!("expected a real, found {}", render(s.value))))
    }

    /// An entity reference attribute.
    pub fn reference(&self, entity: &str, name: &'static str) -> Result<u64, SchemaError> {
        let s = self.slot(entity, name)?;
        s.value.as_reference().ok_or_else(|| {
            self.slot_error(
                &s,
                format!("expected a reference, found {}", render(s.value)),
            )
        })
    }

    /// An OPTIONAL entity reference attribute: `None` for `$`.
    pub fn optional_reference(
        &self,
        entity: &str,
        name: &'static str,
    ) -> Result<Option<u64>, SchemaError> {
        let s = self.slot(entity, name)?;
        match s.value {
            Parameter::Null => Ok(None),
            v => v.as_reference().map(Some).ok_or_else(|| {
                self.slot_error(
                    &s,
                    format!("expected a reference or $, found {}", render(v)),
                )
            }),
        }
    }

    /// A BOOLEAN attribute (`.T.` or `.F.`).
    pub fn boolean(&self, entity: &str, name: &'static str) -> Result<bool, SchemaError> {
        let s = self.slot(entity, name)?;
        match s.value.as_enumeration() {
            Some("T") => Ok(true),
            Some("F") => Ok(false),
            _ => Err(self.slot_error(
                &s,
                format!("expected .T. or .F., found {}", render(s.value)),
            )),
        }
    }

    /// An attribute whose values are checked by the caller: its raw parameter and a way to
    /// report an error located at it.
    pub fn checked<T>(
        &self,
        entity: &str,
        name: &'static str,
        f: impl FnOnce(&'i Parameter<'a>) -> Result<T, String>,
    ) -> Result<T, SchemaError> {
        let s = self.slot(entity, name)?;
        f(s.value).map_err(|m| self.slot_error(&s, m))
    }

    /// A STRING attribute.
    pub fn string(&self, entity: &str, name: &'static str) -> Result<StepString<'a>, SchemaError> {
        let s = self.slot(entity, name)?;
        s.value.as_string().cloned().ok_or_else(|| {
            self.slot_error(
                &s,
                format!("expected a string, found {}", s.value.kind_name()),
            )
        })
    }

    /// A LIST OF REAL attribute (integers accepted as reals).
    pub fn reals(&self, entity: &str, name: &'static str) -> Result<Vec<f64>, SchemaError> {
        let s = self.slot(entity, name)?;
        self.list_of(&s, s.value, "a real", Parameter::as_real)
    }

    /// A LIST OF INTEGER attribute.
    pub fn integers(&self, entity: &str, name: &'static str) -> Result<Vec<i64>, SchemaError> {
        let s = self.slot(entity, name)?;
        self.list_of(&s, s.value, "an integer", Parameter::as_integer)
    }

    /// A LIST OF entity reference attribute.
    pub fn references(&self, entity: &str, name: &'static str) -> Result<Vec<u64>, SchemaError> {
        let s = self.slot(entity, name)?;
        self.list_of(&s, s.value, "a reference", Parameter::as_reference)
    }

    /// A LIST OF LIST OF entity reference attribute.
    pub fn reference_grid(
        &self,
        entity: &str,
        name: &'static str,
    ) -> Result<Vec<Vec<u64>>, SchemaError> {
        let s = self.slot(entity, name)?;
        self.grid_of(&s, "a reference", Parameter::as_reference)
    }

    /// A LIST OF LIST OF REAL attribute.
    pub fn real_grid(
        &self,
        entity: &str,
        name: &'static str,
    ) -> Result<Vec<Vec<f64>>, SchemaError> {
        let s = self.slot(entity, name)?;
        self.grid_of(&s, "a real", Parameter::as_real)
    }

    fn list_of<T>(
        &self,
        s: &Slot<'i, 'a>,
        value: &Parameter<'a>,
        what: &str,
        f: impl Fn(&Parameter<'a>) -> Option<T>,
    ) -> Result<Vec<T>, SchemaError> {
        let Some(list) = value.as_list() else {
            return Err(self.slot_error(s, format!("expected a list, found {}", value.kind_name())));
        };
        // Sized once: collecting into `Result<Vec<_>>` cannot use the length and re-grows
        // the vector element by element (a visible cost on files with large nets).
        let mut out = Vec::with_capacity(list.len());
        for (i, p) in list.iter().enumerate() {
            match f(p) {
                Some(v) => out.push(v),
                None => {
                    return Err(self.slot_error(
                        s,
                        format!("element {} : expected {what}, found {}", i + 1, render(p)),
                    ));
                }
            }
        }
        Ok(out)
    }

    fn grid_of<T>(
        &self,
        s: &Slot<'i, 'a>,
        what: &str,
        f: impl Fn(&Parameter<'a>) -> Option<T> + Copy,
    ) -> Result<Vec<Vec<T>>, SchemaError> {
        let Some(rows) = s.value.as_list() else {
            return Err(self.slot_error(
                s,
                format!("expected a list of lists, found {}", s.value.kind_name()),
            ));
        };
        rows.iter()
            .enumerate()
            .map(|(i, row)| {
                self.list_of(s, row, what, f).map_err(|e| SchemaError {
                    message: format!("row {}: {}", i + 1, e.message),
                    ..e
                })
            })
            .collect()
    }
}

impl Attributes<'_, '_> {
    /// Each reference inside an attribute [`REFERENCE_TYPES`] declares, with the attribute's
    /// position and name, the entity declaring it, and the types it allows.
    fn declared_references(
        &self,
        mut f: impl FnMut(u64, (usize, &'static str), &'static str, &'static [&'static str]),
    ) {
        for s in &self.slots {
            let Some((_, _, allowed)) = REFERENCE_TYPES
                .iter()
                .find(|(e, a, _)| *e == s.entity && *a == s.name)
            else {
                continue;
            };
            let mut stack = vec![s.value];
            while let Some(p) = stack.pop() {
                match p {
                    Parameter::Reference(id) => f(*id, (s.position, s.name), s.entity, allowed),
                    Parameter::List(l) => stack.extend(l.iter().rev()),
                    Parameter::Typed(_, inner) => stack.push(inner),
                    _ => {}
                }
            }
        }
    }
}

/// A short rendering of a parameter for messages.
pub(crate) fn render(p: &Parameter<'_>) -> String {
    match p {
        Parameter::Integer(i) => i.to_string(),
        Parameter::Real(r) => format!("{r:?}"),
        Parameter::Enumeration(e) => format!(".{e}."),
        Parameter::Reference(r) => format!("#{r}"),
        Parameter::String(s) => format!("'{}'", s.raw),
        other => other.kind_name().to_owned(),
    }
}

/// EXPRESS LOGICAL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Logical {
    /// `.T.`
    True,
    /// `.F.`
    False,
    /// `.U.`
    Unknown,
}

impl From<bool> for Logical {
    fn from(v: bool) -> Self {
        if v { Logical::True } else { Logical::False }
    }
}

impl Logical {
    /// `Some(bool)` for `.T.`/`.F.`, `None` for `.U.`.
    pub fn as_bool(self) -> Option<bool> {
        match self {
            Logical::True => Some(true),
            Logical::False => Some(false),
            Logical::Unknown => None,
        }
    }
}

/// `cartesian_point(name, coordinates: LIST [1:3] OF length_measure)` (ISO 10303-42).
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianPoint<'a> {
    /// `name` (absent only in a complex instance without REPRESENTATION_ITEM).
    pub name: Option<StepString<'a>>,
    /// 1 to 3 coordinates (owned when read, borrowed when written).
    pub coordinates: Cow<'a, [f64]>,
}

impl<'a> CartesianPoint<'a> {
    /// Fast path for the commonest instance of all: the coordinates of a simple
    /// `CARTESIAN_POINT('name',(x,y[,z]))` read straight from the body text, without
    /// building a syntax tree. Returns `None` for any other shape (comments, integers,
    /// escapes in the name, errors...); callers then use [`CartesianPoint::from_instance`],
    /// which handles and reports everything. Same values as the general path, bit for bit
    /// (both use [`parse_step_real`](crate::real::parse_step_real)).
    fn coordinates_from_text(text: &str, raw: &RawInstance<'_>) -> Option<([f64; 3], usize)> {
        let b = raw.body(text).as_bytes();
        if raw.keyword_len() != "CARTESIAN_POINT".len() || !b.starts_with(b"CARTESIAN_POINT") {
            return None;
        }
        let mut i = "CARTESIAN_POINT".len();
        let ws = |i: &mut usize| {
            while matches!(b.get(*i), Some(b' ' | b'\t' | b'\r' | b'\n')) {
                *i += 1;
            }
        };
        let expect = |i: &mut usize, c: u8| {
            ws(i);
            if b.get(*i) == Some(&c) {
                *i += 1;
                Some(())
            } else {
                None
            }
        };
        expect(&mut i, b'(')?;
        expect(&mut i, b'\'')?;
        loop {
            let p = i + b.get(i..)?.iter().position(|&c| c == b'\'')?;
            if b.get(p + 1) == Some(&b'\'') {
                i = p + 2;
            } else {
                i = p + 1;
                break;
            }
        }
        expect(&mut i, b',')?;
        expect(&mut i, b'(')?;
        let mut out = [0.0; 3];
        let mut n = 0;
        loop {
            ws(&mut i);
            let (value, end) = crate::real::step_real_at(b, i).ok()?;
            // The general lexer takes the maximal run of number characters as one token:
            // `1.5E3X` or `1.5.2` must fail here too, not read as `1.5E3`, `1.5`.
            if b.get(end).is_some_and(|c| {
                c.is_ascii_alphanumeric() || matches!(c, b'.' | b'+' | b'-' | b'_')
            }) {
                return None;
            }
            i = end;
            *out.get_mut(n)? = value;
            n += 1;
            ws(&mut i);
            match b.get(i) {
                Some(b',') => i += 1,
                Some(b')') => {
                    i += 1;
                    break;
                }
                _ => return None,
            }
        }
        expect(&mut i, b')')?;
        ws(&mut i);
        (i == b.len()).then_some((out, n))
    }

    /// Reads a `CARTESIAN_POINT` (simple or complex).
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let a = Attributes::of(inst, at)?;
        refuse_unknown_data(inst, &a)?;
        if !a.has("CARTESIAN_POINT") {
            return Err(a.error(format!(
                "expected a CARTESIAN_POINT, found {}",
                a.entity_type()
            )));
        }
        let coordinates = a.reals("CARTESIAN_POINT", "coordinates")?;
        if coordinates.is_empty() || coordinates.len() > 3 {
            let s = a.slot("CARTESIAN_POINT", "coordinates")?;
            return Err(a.slot_error(
                &s,
                format!("expected 1 to 3 coordinates, found {}", coordinates.len()),
            ));
        }
        Ok(CartesianPoint {
            name: a.string("REPRESENTATION_ITEM", "name").ok(),
            coordinates: Cow::Owned(coordinates),
        })
    }
}

/// One list per parametric direction of a B-spline (one for a curve, u then v for a
/// surface), read as a slice of the lists. Held without an outer vector: every B-spline
/// record of a file has two of these, and an outer vector was an allocation each.
#[derive(Debug, Clone, PartialEq)]
pub struct PerDirection<T> {
    lists: [Vec<T>; 2],
    count: u8,
}

impl<T> PerDirection<T> {
    /// A curve's one list.
    pub fn curve(list: Vec<T>) -> Self {
        PerDirection {
            lists: [list, Vec::new()],
            count: 1,
        }
    }

    /// A surface's lists in u and in v.
    pub fn surface(u: Vec<T>, v: Vec<T>) -> Self {
        PerDirection {
            lists: [u, v],
            count: 2,
        }
    }
}

impl<T> std::ops::Deref for PerDirection<T> {
    type Target = [Vec<T>];

    fn deref(&self) -> &[Vec<T>] {
        self.lists
            .get(..usize::from(self.count))
            .unwrap_or_default()
    }
}

impl<'a, T> IntoIterator for &'a PerDirection<T> {
    type Item = &'a Vec<T>;
    type IntoIter = std::slice::Iter<'a, Vec<T>>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// How a B-spline's knots are given: explicitly (`*_WITH_KNOTS`) or implied by a subtype.
#[derive(Debug, Clone, PartialEq)]
pub enum KnotSpec<'a> {
    /// `b_spline_curve_with_knots` / `b_spline_surface_with_knots`: one
    /// `(multiplicities, distinct knots)` pair per parametric direction, and `knot_spec`.
    Explicit {
        /// Per direction (1 for a curve, u then v for a surface): multiplicities.
        multiplicities: PerDirection<i64>,
        /// Per direction: distinct knot values.
        knots: PerDirection<f64>,
        /// `knot_spec` without dots (`UNSPECIFIED`, `PIECEWISE_BEZIER_KNOTS`...).
        knot_spec: &'a str,
    },
    /// `bezier_curve` / `bezier_surface`: piecewise Bezier knots implied.
    Bezier,
    /// `uniform_curve` / `uniform_surface`: uniform knots implied.
    Uniform,
    /// `quasi_uniform_curve` / `quasi_uniform_surface`: clamped uniform knots implied.
    QuasiUniform,
}

/// The B-spline entity types as files spell them: the simple types, and the complex
/// instances of the rational ones with every partial in the alphabetical order that
/// ISO 10303-21's external mapping gives complex instances (as Open CASCADE writes them).
const BSPLINE_ENTITY_TYPES: &[&str] = &[
    "B_SPLINE_CURVE_WITH_KNOTS",
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "BEZIER_CURVE",
    "BEZIER_SURFACE",
    "UNIFORM_CURVE",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_CURVE",
    "QUASI_UNIFORM_SURFACE",
    "(BOUNDED_CURVE,B_SPLINE_CURVE,B_SPLINE_CURVE_WITH_KNOTS,CURVE,GEOMETRIC_REPRESENTATION_ITEM,RATIONAL_B_SPLINE_CURVE,REPRESENTATION_ITEM)",
    "(BOUNDED_SURFACE,B_SPLINE_SURFACE,B_SPLINE_SURFACE_WITH_KNOTS,GEOMETRIC_REPRESENTATION_ITEM,RATIONAL_B_SPLINE_SURFACE,REPRESENTATION_ITEM,SURFACE)",
];

/// A B-spline record's `entity_type` for the type `written`: one of
/// [`BSPLINE_ENTITY_TYPES`] borrowed, any other spelling copied.
pub(crate) fn bspline_entity_type(written: &str) -> Cow<'static, str> {
    BSPLINE_ENTITY_TYPES
        .iter()
        .find(|t| **t == written)
        .map_or_else(|| Cow::Owned(written.to_owned()), |t| Cow::Borrowed(*t))
}

/// Which knot subtype partial the instance carries (exactly one is required, WR1 of
/// `b_spline_curve`).
fn knot_subtype(a: &Attributes<'_, '_>, kind: &str) -> Result<(&'static str, usize), SchemaError> {
    let names: [(&'static str, usize); 4] = if kind == "CURVE" {
        [
            ("B_SPLINE_CURVE_WITH_KNOTS", 0),
            ("BEZIER_CURVE", 1),
            ("UNIFORM_CURVE", 2),
            ("QUASI_UNIFORM_CURVE", 3),
        ]
    } else {
        [
            ("B_SPLINE_SURFACE_WITH_KNOTS", 0),
            ("BEZIER_SURFACE", 1),
            ("UNIFORM_SURFACE", 2),
            ("QUASI_UNIFORM_SURFACE", 3),
        ]
    };
    let found: Vec<_> = names.iter().filter(|(n, _)| a.has(n)).copied().collect();
    match found.as_slice() {
        [one] => Ok(*one),
        [] => Err(a.error(format!(
            "a B_SPLINE_{kind} must also be one of {} (none found)",
            names.map(|n| n.0).join(", ")
        ))),
        _ => Err(a.error(format!(
            "more than one knot subtype: {}",
            found.iter().map(|f| f.0).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// A B-spline curve of any Part 42 subtype, rational or not.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve<'a> {
    /// `name` (from REPRESENTATION_ITEM; `None` if a complex instance lacks it).
    pub name: Option<StepString<'a>>,
    /// `degree`.
    pub degree: i64,
    /// `control_points_list`: references to CARTESIAN_POINTs.
    pub control_points: Vec<u64>,
    /// `curve_form` without dots.
    pub curve_form: &'a str,
    /// `closed_curve`.
    pub closed_curve: Logical,
    /// `self_intersect`.
    pub self_intersect: Logical,
    /// The knots, explicit or implied.
    pub knots: KnotSpec<'a>,
    /// `weights_data` of RATIONAL_B_SPLINE_CURVE.
    pub weights: Option<Vec<f64>>,
    /// The entity type as written (`B_SPLINE_CURVE_WITH_KNOTS` or `(A,B,...)`); borrowed
    /// (no allocation per record) for the simple B-spline types and the rational complex
    /// instances with all their partials in alphabetical order.
    pub entity_type: Cow<'static, str>,
}

impl<'a> BSplineCurve<'a> {
    /// Reads any B_SPLINE_CURVE instance (simple or complex, partials in any order).
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let a = Attributes::of(inst, at)?;
        refuse_unknown_data(inst, &a)?;
        if !a.has("B_SPLINE_CURVE") {
            return Err(a.error(format!(
                "expected a B_SPLINE_CURVE, found {}",
                a.entity_type()
            )));
        }
        const E: &str = "B_SPLINE_CURVE";
        let knots = match knot_subtype(&a, "CURVE")? {
            (_, 0) => KnotSpec::Explicit {
                multiplicities: PerDirection::curve(
                    a.integers("B_SPLINE_CURVE_WITH_KNOTS", "knot_multiplicities")?,
                ),
                knots: PerDirection::curve(a.reals("B_SPLINE_CURVE_WITH_KNOTS", "knots")?),
                knot_spec: a.enumeration("B_SPLINE_CURVE_WITH_KNOTS", "knot_spec")?,
            },
            (_, 1) => KnotSpec::Bezier,
            (_, 2) => KnotSpec::Uniform,
            _ => KnotSpec::QuasiUniform,
        };
        let weights = if a.has("RATIONAL_B_SPLINE_CURVE") {
            Some(a.reals("RATIONAL_B_SPLINE_CURVE", "weights_data")?)
        } else {
            None
        };
        Ok(BSplineCurve {
            name: a.string("REPRESENTATION_ITEM", "name").ok(),
            degree: a.integer(E, "degree")?,
            control_points: a.references(E, "control_points_list")?,
            curve_form: a.enumeration(E, "curve_form")?,
            closed_curve: a.logical(E, "closed_curve")?,
            self_intersect: a.logical(E, "self_intersect")?,
            knots,
            weights,
            entity_type: bspline_entity_type(a.entity_type()),
        })
    }
}

/// A B-spline surface of any Part 42 subtype, rational or not.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurface<'a> {
    /// `name` (from REPRESENTATION_ITEM).
    pub name: Option<StepString<'a>>,
    /// `u_degree`.
    pub u_degree: i64,
    /// `v_degree`.
    pub v_degree: i64,
    /// `control_points_list`: outer index u, inner index v.
    pub control_points: Vec<Vec<u64>>,
    /// `surface_form` without dots.
    pub surface_form: &'a str,
    /// `u_closed`.
    pub u_closed: Logical,
    /// `v_closed`.
    pub v_closed: Logical,
    /// `self_intersect`.
    pub self_intersect: Logical,
    /// The knots (u then v for the explicit form).
    pub knots: KnotSpec<'a>,
    /// `weights_data` of RATIONAL_B_SPLINE_SURFACE, same shape as the net.
    pub weights: Option<Vec<Vec<f64>>>,
    /// The entity type as written (see [`BSplineCurve::entity_type`]).
    pub entity_type: Cow<'static, str>,
}

impl<'a> BSplineSurface<'a> {
    /// Reads any B_SPLINE_SURFACE instance (simple or complex, partials in any order).
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let a = Attributes::of(inst, at)?;
        refuse_unknown_data(inst, &a)?;
        if !a.has("B_SPLINE_SURFACE") {
            return Err(a.error(format!(
                "expected a B_SPLINE_SURFACE, found {}",
                a.entity_type()
            )));
        }
        const E: &str = "B_SPLINE_SURFACE";
        const K: &str = "B_SPLINE_SURFACE_WITH_KNOTS";
        let knots = match knot_subtype(&a, "SURFACE")? {
            (_, 0) => KnotSpec::Explicit {
                multiplicities: PerDirection::surface(
                    a.integers(K, "u_multiplicities")?,
                    a.integers(K, "v_multiplicities")?,
                ),
                knots: PerDirection::surface(a.reals(K, "u_knots")?, a.reals(K, "v_knots")?),
                knot_spec: a.enumeration(K, "knot_spec")?,
            },
            (_, 1) => KnotSpec::Bezier,
            (_, 2) => KnotSpec::Uniform,
            _ => KnotSpec::QuasiUniform,
        };
        let weights = if a.has("RATIONAL_B_SPLINE_SURFACE") {
            Some(a.real_grid("RATIONAL_B_SPLINE_SURFACE", "weights_data")?)
        } else {
            None
        };
        Ok(BSplineSurface {
            name: a.string("REPRESENTATION_ITEM", "name").ok(),
            u_degree: a.integer(E, "u_degree")?,
            v_degree: a.integer(E, "v_degree")?,
            control_points: a.reference_grid(E, "control_points_list")?,
            surface_form: a.enumeration(E, "surface_form")?,
            u_closed: a.logical(E, "u_closed")?,
            v_closed: a.logical(E, "v_closed")?,
            self_intersect: a.logical(E, "self_intersect")?,
            knots,
            weights,
            entity_type: bspline_entity_type(a.entity_type()),
        })
    }
}

/// Which B-spline entity an instance is, from its keyword(s) alone (no attribute checks):
/// a cheap filter for readers that want only the B-splines of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BSplineKind {
    /// A B_SPLINE_CURVE (any subtype).
    Curve,
    /// A B_SPLINE_SURFACE (any subtype).
    Surface,
}

/// Classifies an instance as a B-spline curve or surface by its entity names.
pub fn bspline_kind(body: &Body<'_>) -> Option<BSplineKind> {
    let mut kind = None;
    for r in body.records() {
        match canonical_name(r.keyword) {
            "B_SPLINE_CURVE"
            | "B_SPLINE_CURVE_WITH_KNOTS"
            | "BEZIER_CURVE"
            | "UNIFORM_CURVE"
            | "QUASI_UNIFORM_CURVE" => kind = Some(BSplineKind::Curve),
            "B_SPLINE_SURFACE"
            | "B_SPLINE_SURFACE_WITH_KNOTS"
            | "BEZIER_SURFACE"
            | "UNIFORM_SURFACE"
            | "QUASI_UNIFORM_SURFACE" => kind = Some(BSplineKind::Surface),
            _ => {}
        }
    }
    kind
}

/// The keywords of the B-spline surface entities (ISO 10303-42 4.4.39-4.4.44).
const BSPLINE_SURFACES: [&str; 6] = [
    "B_SPLINE_SURFACE",
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "BEZIER_SURFACE",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_SURFACE",
    "RATIONAL_B_SPLINE_SURFACE",
];

/// Whether instance `raw` names a B-spline surface entity, from its text alone: the keyword
/// of a simple instance, or any of those keywords inside a complex one. No decoding, so a
/// reader that leaves B-spline surfaces to [`Scanned::bspline`] can skip them cheaply
/// (that decoder still checks the instance and locates its errors). `text` is the text
/// scanned.
pub fn names_bspline_surface(text: &str, raw: &RawInstance<'_>) -> bool {
    match raw.keyword(text) {
        Some(k) => BSPLINE_SURFACES.contains(&canonical_name(k)),
        // These three are inside every other name of the list.
        None => ["B_SPLINE_SURFACE", "BEZIER_SURFACE", "UNIFORM_SURFACE"]
            .iter()
            .any(|k| raw.body(text).contains(k)),
    }
}

/// A B-spline curve or surface record: what [`Scanned::bspline`] decodes.
#[derive(Debug, Clone, PartialEq)]
pub enum BSpline<'a> {
    /// A `b_spline_curve` (ISO 10303-42 4.4.12) with its knots, explicit or implied by the
    /// subtype, and its weights when rational.
    Curve(BSplineCurve<'a>),
    /// A `b_spline_surface` (ISO 10303-42 4.4.39), likewise.
    Surface(BSplineSurface<'a>),
}

/// Why an instance did not decode into its record: its syntax (located by line, column and
/// `#id`) or its attributes against the EXPRESS definition.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// The instance's parameters do not follow ISO 10303-21.
    #[error(transparent)]
    Syntax(#[from] ParseError),
    /// The parameters do not match the entity's attributes.
    #[error(transparent)]
    Schema(#[from] SchemaError),
}

impl<'a> Scanned<'a> {
    /// The location of an instance, for schema errors.
    pub fn at(&self, raw: &RawInstance<'_>) -> At {
        let (line, column) = self.locate(raw.offset());
        At {
            id: raw.id,
            line,
            column,
        }
    }

    /// Decodes instance `raw` as a B-spline curve or surface, simple or complex, in any
    /// partial order, with implicit-knot subtypes (ISO 10303-42 4.4.12-4.4.17 and
    /// 4.4.39-4.4.44); `Ok(None)` when it is another entity.
    ///
    /// The shapes Open CASCADE, FreeCAD and nurbsx write are read from the body text in one
    /// pass (private to this decoder); any other shape, and anything irregular, is decoded
    /// by the grammar and read by attribute name, which gives the same record or the
    /// located error.
    #[inline]
    pub fn bspline(&self, raw: &RawInstance<'a>) -> Result<Option<BSpline<'a>>, DecodeError> {
        if let Some(record) = super::bspline_text::read(self.text, raw, self.param_limits()) {
            return Ok(Some(record));
        }
        let inst = self.decode(raw)?;
        Ok(match bspline_kind(&inst.body) {
            None => None,
            Some(BSplineKind::Curve) => Some(BSpline::Curve(BSplineCurve::from_instance(
                &inst,
                self.at(raw),
            )?)),
            Some(BSplineKind::Surface) => Some(BSpline::Surface(BSplineSurface::from_instance(
                &inst,
                self.at(raw),
            )?)),
        })
    }

    /// Decodes instance `raw` as a `cartesian_point` (ISO 10303-42 4.4.2): its first three
    /// coordinates (zeros past its dimension) and its dimension. The usual simple instance
    /// is read from its text in one pass; any other shape through the grammar, by attribute
    /// name, with the same values or the located error.
    #[inline]
    pub fn cartesian_point(&self, raw: &RawInstance<'a>) -> Result<([f64; 3], usize), DecodeError> {
        if let Some(point) = CartesianPoint::coordinates_from_text(self.text, raw) {
            return Ok(point);
        }
        let p = CartesianPoint::from_instance(&self.decode(raw)?, self.at(raw))?;
        let mut c = [0.0; 3];
        for (k, v) in p.coordinates.iter().take(3).enumerate() {
            c[k] = *v;
        }
        Ok((c, p.coordinates.len()))
    }
}

impl Scanned<'_> {
    /// The entity types instance `#id` is of, supertypes included (ISO 10303-11 SUBTYPE OF,
    /// as [`SUPERTYPE_CHAINS`] and, for a complex instance, its partial records name them);
    /// `None` when the instance is missing, does not decode, or names an entity type the
    /// tables do not hold (it may be a subtype of anything).
    fn types_of(&self, id: u64) -> Option<Cow<'static, [&'static str]>> {
        let raw = self.get(id)?;
        if let Some(keyword) = raw.keyword(self.text) {
            let name = canonical_name(keyword);
            return SUPERTYPE_CHAINS
                .iter()
                .find(|(e, _)| *e == name)
                .map(|(_, chain)| Cow::Borrowed(*chain));
        }
        let inst = self.decode(raw).ok()?;
        let mut types = Vec::new();
        for r in inst.body.records() {
            let name = canonical_name(r.keyword);
            match SUPERTYPE_CHAINS.iter().find(|(e, _)| *e == name) {
                Some((_, chain)) => types.extend_from_slice(chain),
                None => types.push(OWN_ATTRIBUTES.iter().find(|(e, _)| *e == name)?.0),
            }
        }
        Some(Cow::Owned(types))
    }

    /// Every reference of an instance, in an attribute whose EXPRESS type
    /// [`REFERENCE_TYPES`] declares, that names an instance of another type (ISO 10303-21
    /// clause 11: an instance name refers to an entity instance of the attribute's type;
    /// ISO 10303-11 subtypes admitted). Missing targets are the dangling-reference check's;
    /// targets of entity types the tables do not hold are not judged.
    pub fn reference_type_errors(&self, a: &Attributes<'_, '_>) -> Vec<SchemaError> {
        let mut errors = Vec::new();
        a.declared_references(|id, attribute, entity, allowed| {
            let Some(types) = self.types_of(id) else {
                return;
            };
            if types.iter().any(|t| allowed.contains(t)) {
                return;
            }
            let found = self
                .get(id)
                .and_then(|raw| raw.keyword(self.text))
                .map_or_else(
                    || "complex instance".to_owned(),
                    |k| canonical_name(k).to_owned(),
                );
            errors.push(SchemaError {
                entity: a.at.id,
                entity_type: entity.to_owned(),
                attribute: Some(attribute),
                message: format!(
                    "refers to #{id}, a {found}; the attribute's type allows {} (or a subtype)",
                    allowed.join(" or ")
                ),
                line: a.at.line,
                column: a.at.column,
            });
        });
        errors
    }
}

/// A unit (ISO 10303-41): only what the reader needs to find the length unit.
#[derive(Debug, Clone, PartialEq)]
pub enum Unit<'a> {
    /// `si_unit(prefix, name)`: prefix (`MILLI`...) or `None` for `$`, and the name
    /// (`METRE`, `RADIAN`...). `length` is true for a LENGTH_UNIT or a `METRE`.
    Si {
        /// `prefix` without dots.
        prefix: Option<&'a str>,
        /// `name` without dots.
        name: &'a str,
        /// Whether this is a length unit.
        length: bool,
    },
    /// `conversion_based_unit(name, conversion_factor)`.
    ConversionBased {
        /// `name` (`INCH`, `FOOT`...).
        name: StepString<'a>,
        /// The MEASURE_WITH_UNIT giving the factor.
        conversion_factor: u64,
        /// Whether it is a LENGTH_UNIT.
        length: bool,
        /// Whether it is a PLANE_ANGLE_UNIT.
        plane_angle: bool,
    },
    /// Any other named unit (`length` tells whether LENGTH_UNIT is among its partials).
    Other {
        /// The entity type as written.
        entity_type: String,
        /// Whether it is a LENGTH_UNIT.
        length: bool,
    },
}

impl<'a> Unit<'a> {
    /// Reads a unit instance: `( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )`,
    /// `SI_UNIT(*,.MILLI.,.METRE.)`, `( CONVERSION_BASED_UNIT('INCH',#5) LENGTH_UNIT()
    /// NAMED_UNIT(#6) )`...
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let a = Attributes::of(inst, at)?;
        let length_partial = a.has("LENGTH_UNIT");
        if a.has("SI_UNIT") {
            let prefix = match a.param("SI_UNIT", "prefix")? {
                Parameter::Null => None,
                _ => Some(a.enumeration("SI_UNIT", "prefix")?),
            };
            let name = a.enumeration("SI_UNIT", "name")?;
            Ok(Unit::Si {
                prefix,
                name,
                length: length_partial || name == "METRE",
            })
        } else if a.has("CONVERSION_BASED_UNIT") {
            let factor = a.param("CONVERSION_BASED_UNIT", "conversion_factor")?;
            let Some(conversion_factor) = factor.as_reference() else {
                return Err(a.error(format!(
                    "conversion_factor: expected a reference, found {}",
                    factor.kind_name()
                )));
            };
            Ok(Unit::ConversionBased {
                name: a.string("CONVERSION_BASED_UNIT", "name")?,
                conversion_factor,
                length: length_partial,
                plane_angle: a.has("PLANE_ANGLE_UNIT"),
            })
        } else {
            Ok(Unit::Other {
                entity_type: a.entity_type().to_owned(),
                length: length_partial,
            })
        }
    }
}

/// `measure_with_unit(value_component, unit_component)` and its subtypes
/// (`LENGTH_MEASURE_WITH_UNIT`, `UNCERTAINTY_MEASURE_WITH_UNIT`).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasureWithUnit<'a> {
    /// The value (a typed `LENGTH_MEASURE(25.4)` is unwrapped).
    pub value: f64,
    /// The measure's type keyword when typed (`LENGTH_MEASURE`).
    pub measure_type: Option<&'a str>,
    /// The unit instance.
    pub unit: u64,
}

impl<'a> MeasureWithUnit<'a> {
    /// Reads a MEASURE_WITH_UNIT (or subtype) instance.
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Self, SchemaError> {
        let a = Attributes::of(inst, at)?;
        if !a.has("MEASURE_WITH_UNIT") {
            return Err(a.error(format!(
                "expected a MEASURE_WITH_UNIT, found {}",
                a.entity_type()
            )));
        }
        let v = a.param("MEASURE_WITH_UNIT", "value_component")?;
        let (value, measure_type) = match v {
            Parameter::Typed(k, inner) => (inner.as_real(), Some(*k)),
            other => (other.as_real(), None),
        };
        let Some(value) = value else {
            return Err(a.error(format!(
                "value_component: expected a real, found {}",
                v.kind_name()
            )));
        };
        let u = a.param("MEASURE_WITH_UNIT", "unit_component")?;
        let Some(unit) = u.as_reference() else {
            return Err(a.error(format!(
                "unit_component: expected a reference, found {}",
                u.kind_name()
            )));
        };
        Ok(MeasureWithUnit {
            value,
            measure_type,
            unit,
        })
    }
}

/// A representation context with its global units and uncertainty (ISO 10303-43:
/// `( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#23))
/// GLOBAL_UNIT_ASSIGNED_CONTEXT((#20,#21,#22)) REPRESENTATION_CONTEXT('',''))`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RepresentationContext {
    /// `coordinate_space_dimension`, when a GEOMETRIC_REPRESENTATION_CONTEXT.
    pub dimension: Option<i64>,
    /// `units` of GLOBAL_UNIT_ASSIGNED_CONTEXT (empty when absent).
    pub units: Vec<u64>,
    /// `uncertainty` of GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT (empty when absent).
    pub uncertainty: Vec<u64>,
}

impl RepresentationContext {
    /// Reads a context instance; `None` if it has no unit or uncertainty assignment.
    pub fn from_instance(inst: &Instance<'_>, at: At) -> Result<Option<Self>, SchemaError> {
        let a = Attributes::of(inst, at)?;
        if !a.has("GLOBAL_UNIT_ASSIGNED_CONTEXT") && !a.has("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT") {
            return Ok(None);
        }
        Ok(Some(RepresentationContext {
            dimension: if a.has("GEOMETRIC_REPRESENTATION_CONTEXT") {
                Some(a.integer(
                    "GEOMETRIC_REPRESENTATION_CONTEXT",
                    "coordinate_space_dimension",
                )?)
            } else {
                None
            },
            units: if a.has("GLOBAL_UNIT_ASSIGNED_CONTEXT") {
                a.references("GLOBAL_UNIT_ASSIGNED_CONTEXT", "units")?
            } else {
                Vec::new()
            },
            uncertainty: if a.has("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT") {
                a.references("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT", "uncertainty")?
            } else {
                Vec::new()
            },
        }))
    }
}

#[cfg(test)]
mod point_text_tests {
    use super::*;
    use crate::Limits;
    use crate::real::write_real;
    use crate::step::scan;
    use proptest::prelude::*;

    fn at(id: u64) -> At {
        At {
            id,
            line: 2,
            column: 1,
        }
    }

    proptest! {
        /// The text reader and the general record path give the same bits, and the text
        /// reader declines (None) rather than guessing on shapes it does not handle.
        #[test]
        fn text_reader_equals_general_path(xs in prop::collection::vec(any::<f64>().prop_filter("finite", |x| x.is_finite()), 1..4), spaced in any::<bool>(), name in "[a-z' ]{0,5}") {
            let mut coords = String::new();
            for (i, x) in xs.iter().enumerate() {
                if i > 0 { coords.push(','); if spaced { coords.push_str(" \n"); } }
                write_real(&mut coords, *x).unwrap();
            }
            let name = name.replace('\'', "''");
            let text = format!("ISO-10303-21;HEADER;ENDSEC;DATA;\n#1=CARTESIAN_POINT( '{name}' ,({coords}) );\nENDSEC;END-ISO-10303-21;");
            let s = scan(&text, &Limits::default()).unwrap();
            let raw = s.get(1).unwrap();
            let (fast, n) = CartesianPoint::coordinates_from_text(&text, raw).unwrap();
            let slow = CartesianPoint::from_instance(&s.decode(raw).unwrap(), at(1)).unwrap();
            prop_assert_eq!(n, xs.len());
            for (f, g) in fast.iter().zip(slow.coordinates.iter()) {
                prop_assert_eq!(f.to_bits(), g.to_bits());
            }
            // The public decoder gives the same.
            prop_assert_eq!(s.cartesian_point(raw).unwrap(), (fast, n));
        }
    }

    #[test]
    fn text_reader_declines_other_shapes() {
        for body in ["(0,1,2)", "(0.,1.,2.,3.)", "(0., /* c */ 1.)", "(1.e5)"] {
            let text = format!(
                "ISO-10303-21;HEADER;ENDSEC;DATA;\n#1=CARTESIAN_POINT('',{body});\nENDSEC;END-ISO-10303-21;"
            );
            let s = scan(&text, &Limits::default()).unwrap();
            assert_eq!(
                CartesianPoint::coordinates_from_text(&text, s.get(1).unwrap()),
                None,
                "{body}"
            );
        }
    }

    /// The text test of B-spline surfaces agrees with the decoded entity names
    /// (`bspline_kind`) on simple, short-named and complex instances of surfaces, curves and
    /// other entities.
    #[test]
    fn bspline_surfaces_are_named_as_decoding_finds() {
        let grid = "((#9,#9),(#9,#9))";
        let bodies = [
            format!("B_SPLINE_SURFACE_WITH_KNOTS('',1,1,{grid},.UNSPECIFIED.,.F.,.F.,.F.,(2,2),(2,2),(0.,1.),(0.,1.),.UNSPECIFIED.)"),
            format!("BSSWK('',1,1,{grid},.UNSPECIFIED.,.F.,.F.,.F.,(2,2),(2,2),(0.,1.),(0.,1.),.UNSPECIFIED.)"),
            format!("BEZIER_SURFACE('',1,1,{grid},.UNSPECIFIED.,.F.,.F.,.F.)"),
            format!("(BOUNDED_SURFACE() B_SPLINE_SURFACE(1,1,{grid},.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS((2,2),(2,2),(0.,1.),(0.,1.),.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(((1.,1.),(1.,1.))) REPRESENTATION_ITEM('') SURFACE())"),
            "(BOUNDED_CURVE() B_SPLINE_CURVE(1,(#9,#9),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((2,2),(0.,1.),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((1.,1.)) REPRESENTATION_ITEM(''))".to_string(),
            "B_SPLINE_CURVE_WITH_KNOTS('',1,(#9,#9),.UNSPECIFIED.,.F.,.F.,(2,2),(0.,1.),.UNSPECIFIED.)".to_string(),
            "PLANE('',#9)".to_string(),
        ];
        for body in &bodies {
            let text = format!(
                "ISO-10303-21;HEADER;ENDSEC;DATA;\n#1={body};\n#9=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;END-ISO-10303-21;"
            );
            let s = scan(&text, &Limits::default()).unwrap();
            let raw = s.get(1).unwrap();
            let decoded = bspline_kind(&s.decode(raw).unwrap().body) == Some(BSplineKind::Surface);
            assert_eq!(names_bspline_surface(&text, raw), decoded, "{body}");
        }
    }

    #[test]
    fn the_decoder_reads_what_the_text_reader_declines() {
        let text = "ISO-10303-21;HEADER;ENDSEC;DATA;\n#1=CARTESIAN_POINT('',(0,1,2));\n#2=CARTESIAN_POINT('',(0., /* c */ 1.));\n#3=CARTESIAN_POINT('',(1.e5));\nENDSEC;END-ISO-10303-21;";
        let s = scan(text, &Limits::default()).unwrap();
        assert_eq!(
            s.cartesian_point(s.get(1).unwrap()).unwrap(),
            ([0., 1., 2.], 3)
        );
        assert_eq!(
            s.cartesian_point(s.get(2).unwrap()).unwrap(),
            ([0., 1., 0.], 2)
        );
        assert!(matches!(
            s.cartesian_point(s.get(3).unwrap()),
            Err(DecodeError::Syntax(_))
        ));
    }
}

#[cfg(test)]
mod reference_type_tests {
    use super::*;
    use crate::Limits;
    use crate::step::scan;

    /// Every declared attribute is an own attribute of its entity in [`OWN_ATTRIBUTES`]
    /// (a misspelt name would silently check nothing).
    #[test]
    fn declared_attributes_exist() {
        for (entity, attribute, allowed) in REFERENCE_TYPES {
            let own = own_attributes(entity).unwrap_or_default();
            assert!(own.contains(attribute), "{entity}.{attribute}");
            assert!(!allowed.is_empty());
        }
    }

    /// The reference-type errors of instance `#id` in a DATA section `data`, as
    /// `(attribute name, message)`.
    fn errors(data: &str, id: u64) -> Vec<(&'static str, String)> {
        let text = format!("ISO-10303-21;HEADER;ENDSEC;DATA;\n{data}\nENDSEC;END-ISO-10303-21;");
        let s = scan(&text, &Limits::default()).unwrap();
        let raw = s.get(id).unwrap();
        let inst = s.decode(raw).unwrap();
        let a = Attributes::of(&inst, s.at(raw)).unwrap();
        s.reference_type_errors(&a)
            .into_iter()
            .map(|e| (e.attribute.unwrap().1, e.message))
            .collect()
    }

    const POINT: &str = "#1=CARTESIAN_POINT('',(0.,0.,0.));#2=DIRECTION('',(0.,0.,1.));";

    #[test]
    fn subtypes_of_the_allowed_type_pass() {
        // FACE_BOUND.bound: LOOP; EDGE_LOOP is LOOP's subtype (through PATH too).
        let data = format!(
            "{POINT}#3=VERTEX_POINT('',#1);#4=LINE('',#1,#5);#5=VECTOR('',#2,1.);\
             #6=EDGE_CURVE('',#3,#3,#4,.T.);#7=ORIENTED_EDGE('',*,*,#6,.T.);\
             #8=EDGE_LOOP('',(#7));#9=FACE_OUTER_BOUND('',#8,.T.);"
        );
        assert_eq!(errors(&data, 9), vec![]);
        assert_eq!(errors(&data, 8), vec![]);
        assert_eq!(errors(&data, 6), vec![]);
    }

    #[test]
    fn a_reference_to_another_type_is_an_error() {
        let data = format!("{POINT}#3=VERTEX_POINT('',#1);#9=FACE_BOUND('',#3,.T.);");
        let e = errors(&data, 9);
        assert_eq!(e.len(), 1, "{e:?}");
        assert_eq!(e[0].0, "bound");
        assert!(
            e[0].1.contains("#3, a VERTEX_POINT") && e[0].1.contains("LOOP"),
            "{e:?}"
        );
        // Each wrong element of a list: EDGE_LOOP.edge_list holds ORIENTED_EDGEs.
        let data = format!("{POINT}#8=EDGE_LOOP('',(#1,#2));");
        assert_eq!(errors(&data, 8).len(), 2);
        // A SELECT: SURFACE_CURVE.associated_geometry is a PCURVE or a SURFACE.
        let data = format!(
            "{POINT}#3=LINE('',#1,#4);#4=VECTOR('',#2,1.);\
             #5=AXIS2_PLACEMENT_3D('',#1,#2,$);#6=PLANE('',#5);\
             #7=SURFACE_CURVE('',#3,(#6,#3),.CURVE_3D.);"
        );
        let e = errors(&data, 7);
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].1.contains("#3, a LINE"), "{e:?}");
    }

    #[test]
    fn complex_and_unknown_targets() {
        // A complex instance whose partials name the allowed type passes; one that does
        // not is an error; a target of an entity type the tables do not hold is not judged.
        let ctx = "#4=( GEOMETRIC_REPRESENTATION_CONTEXT(3) REPRESENTATION_CONTEXT('','') );";
        let data = format!(
            "{POINT}{ctx}#5=SHAPE_REPRESENTATION('',(#1),#4);\
             #6=SHAPE_REPRESENTATION('',(#1),#1);#7=SHAPE_REPRESENTATION('',(#1),#8);\
             #8=SOME_OTHER_CONTEXT('');"
        );
        assert_eq!(errors(&data, 5), vec![]);
        assert_eq!(errors(&data, 6).len(), 1);
        assert_eq!(errors(&data, 7), vec![]);
        let data = format!(
            "{POINT}#4=( BOUNDED_CURVE() CURVE() GEOMETRIC_REPRESENTATION_ITEM() REPRESENTATION_ITEM('') );\
             #5=(REPRESENTATION_ITEM('') GEOMETRIC_REPRESENTATION_ITEM() POINT() );\
             #6=EDGE_CURVE('',#1,#1,#4,.T.);#7=EDGE_CURVE('',#1,#1,#5,.T.);"
        );
        // #6: edge_start/edge_end are points, not vertices; edge_geometry a curve.
        assert_eq!(errors(&data, 6).len(), 2);
        assert_eq!(errors(&data, 7).len(), 3);
    }
}
