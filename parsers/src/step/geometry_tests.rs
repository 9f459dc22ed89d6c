//! Hand-written instances of every record of `geometry`: valid (simple and complex), and
//! each attribute wrong in turn (the error names the attribute, its position and the line).

use super::*;
use crate::Limits;
use crate::step::scan;

fn file(data: &str) -> String {
    format!("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
}

/// Decodes instance #1 of `data` (one instance per line, #1 on line 5).
fn item(data: &str) -> Result<Option<GeometryItem<'static>>, DecodeError> {
    let text: &'static str = Box::leak(file(data).into_boxed_str());
    let s = scan(text, &Limits::default()).expect("scan");
    let raw = s.get(1).expect("#1");
    s.geometry_item(raw)
}

fn record(data: &str) -> GeometryRecord<'static> {
    match item(data) {
        Ok(Some(i)) => i.record,
        other => panic!("{data}: {other:?}"),
    }
}

fn schema_error(data: &str) -> SchemaError {
    match item(data) {
        Err(DecodeError::Schema(e)) => e,
        other => panic!("{data}: expected a schema error, got {other:?}"),
    }
}

#[test]
fn valid_simple_instances() {
    use GeometryRecord as R;
    let cases: Vec<(&str, GeometryRecord<'static>)> = vec![
        (
            "#1=DIRECTION('',(0.,0.,1.));",
            R::Direction {
                direction_ratios: Ratios::new(&[0., 0., 1.]).expect("three ratios"),
            },
        ),
        (
            "#1=VECTOR('',#2,2.5);",
            R::Vector {
                orientation: 2,
                magnitude: 2.5,
            },
        ),
        (
            "#1=AXIS1_PLACEMENT('',#2,$);",
            R::Axis1Placement {
                location: 2,
                axis: None,
            },
        ),
        (
            "#1=AXIS2_PLACEMENT_2D('',#2,#3);",
            R::Axis2Placement2d {
                location: 2,
                ref_direction: Some(3),
            },
        ),
        (
            "#1=AXIS2_PLACEMENT_3D('',#2,#3,$);",
            R::Axis2Placement3d {
                location: 2,
                axis: Some(3),
                ref_direction: None,
            },
        ),
        ("#1=LINE('',#2,#3);", R::Line { pnt: 2, dir: 3 }),
        (
            "#1=CIRCLE('',#2,5);",
            R::Circle {
                position: 2,
                radius: 5.0,
            },
        ),
        (
            "#1=ELLIPSE('',#2,5.,3.);",
            R::Ellipse {
                position: 2,
                semi_axis_1: 5.0,
                semi_axis_2: 3.0,
            },
        ),
        (
            "#1=HYPERBOLA('',#2,5.,3.);",
            R::Hyperbola {
                position: 2,
                semi_axis: 5.0,
                semi_imag_axis: 3.0,
            },
        ),
        (
            "#1=PARABOLA('',#2,0.25);",
            R::Parabola {
                position: 2,
                focal_dist: 0.25,
            },
        ),
        (
            "#1=POLYLINE('',(#2,#3,#4));",
            R::Polyline {
                points: vec![2, 3, 4],
            },
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(#3,PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.5)),.F.,.PARAMETER.);",
            R::TrimmedCurve {
                basis_curve: 2,
                trimming: Box::new(Trimming {
                    trim_1: vec![TrimmingSelect::Point(3), TrimmingSelect::Parameter(0.0)].into(),
                    trim_2: vec![TrimmingSelect::Parameter(1.5)].into(),
                    sense_agreement: false,
                    master_representation: "PARAMETER",
                }),
            },
        ),
        (
            "#1=COMPOSITE_CURVE('',(#2,#3),.U.);",
            R::CompositeCurve {
                segments: vec![2, 3],
                self_intersect: Logical::Unknown,
            },
        ),
        (
            "#1=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#2);",
            R::CompositeCurveSegment {
                transition: "CONTINUOUS",
                same_sense: true,
                parent_curve: 2,
            },
        ),
        (
            "#1=SEAM_CURVE('',#2,(#3,#4),.PCURVE_S1.);",
            R::SurfaceCurve {
                curve_3d: 2,
                associated_geometry: vec![3, 4].into(),
                master_representation: "PCURVE_S1",
            },
        ),
        (
            "#1=PCURVE('',#2,#3);",
            R::Pcurve {
                basis_surface: 2,
                reference_to_curve: 3,
            },
        ),
        (
            "#1=DEFINITIONAL_REPRESENTATION('',(#2),#3);",
            R::DefinitionalRepresentation {
                items: vec![2].into(),
                context_of_items: 3,
            },
        ),
        ("#1=PLANE('',#2);", R::Plane { position: 2 }),
        (
            "#1=CYLINDRICAL_SURFACE('',#2,4.);",
            R::CylindricalSurface {
                position: 2,
                radius: 4.0,
            },
        ),
        (
            "#1=CONICAL_SURFACE('',#2,4.,0.5);",
            R::ConicalSurface {
                position: 2,
                radius: 4.0,
                semi_angle: 0.5,
            },
        ),
        (
            "#1=SPHERICAL_SURFACE('',#2,4.);",
            R::SphericalSurface {
                position: 2,
                radius: 4.0,
            },
        ),
        (
            "#1=TOROIDAL_SURFACE('',#2,10.,2.);",
            R::ToroidalSurface {
                position: 2,
                major_radius: 10.0,
                minor_radius: 2.0,
                select_outer: None,
            },
        ),
        (
            "#1=DEGENERATE_TOROIDAL_SURFACE('',#2,1.,2.,.T.);",
            R::ToroidalSurface {
                position: 2,
                major_radius: 1.0,
                minor_radius: 2.0,
                select_outer: Some(true),
            },
        ),
        (
            "#1=SURFACE_OF_LINEAR_EXTRUSION('',#2,#3);",
            R::SurfaceOfLinearExtrusion {
                swept_curve: 2,
                extrusion_axis: 3,
            },
        ),
        (
            "#1=SURFACE_OF_REVOLUTION('',#2,#3);",
            R::SurfaceOfRevolution {
                swept_curve: 2,
                axis_position: 3,
            },
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,1.,-2.,3.,.T.,.F.);",
            R::RectangularTrimmedSurface {
                basis_surface: 2,
                bounds: Box::new(RectangularTrim {
                    u1: 0.0,
                    u2: 1.0,
                    v1: -2.0,
                    v2: 3.0,
                    usense: true,
                    vsense: false,
                }),
            },
        ),
        ("#1=OFFSET_SURFACE('',#2,1.,.F.);", R::Offset { basis: 2 }),
        (
            "#1=VERTEX_POINT('',#2);",
            R::VertexPoint { vertex_geometry: 2 },
        ),
        (
            "#1=EDGE_CURVE('',#2,#3,#4,.T.);",
            R::EdgeCurve {
                edge_start: 2,
                edge_end: 3,
                edge_geometry: 4,
                same_sense: true,
            },
        ),
        (
            "#1=ORIENTED_EDGE('',*,*,#4,.F.);",
            R::OrientedEdge {
                edge_element: 4,
                orientation: false,
            },
        ),
        (
            "#1=EDGE_LOOP('',(#2,#3));",
            R::EdgeLoop {
                edge_list: vec![2, 3],
            },
        ),
        (
            "#1=FACE_OUTER_BOUND('',#2,.T.);",
            R::FaceBound {
                bound: 2,
                orientation: true,
            },
        ),
        (
            "#1=ADVANCED_FACE('',(#2,#3),#4,.F.);",
            R::FaceSurface {
                bounds: vec![2, 3].into(),
                face_geometry: 4,
                same_sense: false,
            },
        ),
        ("#1=VERTEX_LOOP('',#2);", R::VertexLoop { loop_vertex: 2 }),
        (
            "#1=POLY_LOOP('',(#2,#3,#4));",
            R::PolyLoop {
                polygon: vec![2, 3, 4],
            },
        ),
        (
            "#1=OPEN_SHELL('',(#2,#3));",
            R::Shell {
                cfs_faces: vec![2, 3],
                closed: false,
            },
        ),
        (
            "#1=CLOSED_SHELL('',(#2));",
            R::Shell {
                cfs_faces: vec![2],
                closed: true,
            },
        ),
        (
            "#1=ORIENTED_CLOSED_SHELL('',*,#2,.F.);",
            R::OrientedClosedShell {
                closed_shell_element: 2,
                orientation: false,
            },
        ),
        (
            "#1=MANIFOLD_SOLID_BREP('',#2);",
            R::ManifoldSolidBrep {
                outer: 2,
                voids: vec![],
            },
        ),
        (
            "#1=BREP_WITH_VOIDS('',#2,(#3,#4));",
            R::ManifoldSolidBrep {
                outer: 2,
                voids: vec![3, 4],
            },
        ),
        (
            "#1=SHELL_BASED_SURFACE_MODEL('',(#2));",
            R::ShellBasedSurfaceModel {
                sbsm_boundary: vec![2],
            },
        ),
        (
            "#1=FACE_BASED_SURFACE_MODEL('',(#2,#3));",
            R::FaceBasedSurfaceModel {
                fbsm_faces: vec![2, 3],
            },
        ),
        (
            "#1=GEOMETRIC_CURVE_SET('',(#2,#3));",
            R::GeometricSet {
                elements: vec![2, 3],
            },
        ),
        (
            "#1=GEOMETRIC_SET('',(#2));",
            R::GeometricSet { elements: vec![2] },
        ),
    ];
    for (text, expected) in cases {
        assert_eq!(record(text), expected, "{text}");
    }
}

#[test]
fn most_specific_entity_and_name() {
    let i = item("#1=SEAM_CURVE('seam',#2,(#3,#4),.PCURVE_S1.);")
        .unwrap()
        .unwrap();
    assert_eq!(i.entity, "SEAM_CURVE");
    assert_eq!(i.name.unwrap().decode_lossy(), "seam");
    let i = item("#1=DEGENERATE_TOROIDAL_SURFACE('',#2,1.,2.,.F.);")
        .unwrap()
        .unwrap();
    assert_eq!(i.entity, "DEGENERATE_TOROIDAL_SURFACE");
}

#[test]
fn other_entities_are_not_read() {
    for text in [
        "#1=CARTESIAN_POINT('',(0.,0.,0.));",
        "#1=B_SPLINE_CURVE_WITH_KNOTS('',1,(#2,#3),.UNSPECIFIED.,.F.,.F.,(2,2),(0.,1.),.UNSPECIFIED.);",
        "#1=PRODUCT('a','b','',(#2));",
    ] {
        assert_eq!(item(text).unwrap(), None, "{text}");
    }
}

#[test]
fn complex_instances_read_like_simple_ones() {
    // Partials in any order; the unknown partial (REPRESENTATION_ITEM_EXTRA) is ignored.
    let simple = record("#1=CIRCLE('c',#2,5.);");
    let complex = record(
        "#1=( CURVE() GEOMETRIC_REPRESENTATION_ITEM() CIRCLE(5.) CONIC(#2) REPRESENTATION_ITEM('c') );",
    );
    assert_eq!(simple, complex);
    let simple = record(
        "#1=TRIMMED_CURVE('',#2,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.)),.T.,.PARAMETER.);",
    );
    let complex = record(
        "#1=( BOUNDED_CURVE() CURVE() GEOMETRIC_REPRESENTATION_ITEM() REPRESENTATION_ITEM('') TRIMMED_CURVE(#2,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.)),.T.,.PARAMETER.) );",
    );
    assert_eq!(simple, complex);
    let simple = record("#1=ADVANCED_FACE('',(#2),#4,.T.);");
    let complex = record(
        "#1=( ADVANCED_FACE() FACE((#2)) FACE_SURFACE(#4,.T.) REPRESENTATION_ITEM('') TOPOLOGICAL_REPRESENTATION_ITEM() );",
    );
    assert_eq!(simple, complex);
    // A partial with the wrong count is located at that partial.
    let e = schema_error("#1=( CURVE() CIRCLE(5.,6.) CONIC(#2) REPRESENTATION_ITEM('') );");
    assert_eq!(e.entity_type, "CIRCLE");
    assert!(
        e.message.contains("expects 1 parameters, found 2"),
        "{}",
        e.message
    );
}

/// Each attribute of each record, replaced by a value of the wrong type: the error names
/// that attribute, its 1-based position in its entity's own attributes, and line 5.
#[test]
fn each_attribute_wrong() {
    let cases: &[(&str, &str, usize)] = &[
        ("#1=DIRECTION('',#2);", "direction_ratios", 2),
        ("#1=DIRECTION('',(0.,'x'));", "direction_ratios", 2),
        // ISO 10303-42 4.4.3: at most three ratios (held inline, `Ratios`).
        ("#1=DIRECTION('',(0.,0.,1.,2.));", "direction_ratios", 2),
        ("#1=VECTOR('',3.,2.5);", "orientation", 2),
        ("#1=VECTOR('',#2,#3);", "magnitude", 3),
        ("#1=AXIS1_PLACEMENT('',1.,$);", "location", 2),
        ("#1=AXIS1_PLACEMENT('',#2,1.);", "axis", 3),
        ("#1=AXIS2_PLACEMENT_2D('',$,#3);", "location", 2),
        ("#1=AXIS2_PLACEMENT_2D('',#2,.T.);", "ref_direction", 3),
        ("#1=AXIS2_PLACEMENT_3D('','a',$,$);", "location", 2),
        ("#1=AXIS2_PLACEMENT_3D('',#2,(#3),$);", "axis", 3),
        ("#1=AXIS2_PLACEMENT_3D('',#2,$,2.);", "ref_direction", 4),
        ("#1=LINE('',(1.),#3);", "pnt", 2),
        ("#1=LINE('',#2,$);", "dir", 3),
        ("#1=CIRCLE('',$,5.);", "position", 2),
        ("#1=CIRCLE('',#2,#5);", "radius", 3),
        ("#1=ELLIPSE('',#2,'a',3.);", "semi_axis_1", 3),
        ("#1=ELLIPSE('',#2,5.,.T.);", "semi_axis_2", 4),
        ("#1=HYPERBOLA('',#2,$,3.);", "semi_axis", 3),
        ("#1=HYPERBOLA('',#2,5.,#3);", "semi_imag_axis", 4),
        ("#1=PARABOLA('',#2,(1.));", "focal_dist", 3),
        ("#1=POLYLINE('',(#2,3.));", "points", 2),
        (
            "#1=TRIMMED_CURVE('',1.,(#3),(#4),.T.,.PARAMETER.);",
            "basis_curve",
            2,
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(1.5),(#4),.T.,.PARAMETER.);",
            "trim_1",
            3,
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(#3),(),.T.,.PARAMETER.);",
            "trim_2",
            4,
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(#3),(PARAMETER_VALUE('a')),.T.,.PARAMETER.);",
            "trim_2",
            4,
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(#3),(#4),.U.,.PARAMETER.);",
            "sense_agreement",
            5,
        ),
        (
            "#1=TRIMMED_CURVE('',#2,(#3),(#4),.T.,'P');",
            "master_representation",
            6,
        ),
        ("#1=COMPOSITE_CURVE('',#2,.F.);", "segments", 2),
        ("#1=COMPOSITE_CURVE('',(#2),1);", "self_intersect", 3),
        ("#1=COMPOSITE_CURVE_SEGMENT(#3,.T.,#2);", "transition", 1),
        (
            "#1=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.X.,#2);",
            "same_sense",
            2,
        ),
        (
            "#1=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,$);",
            "parent_curve",
            3,
        ),
        ("#1=SURFACE_CURVE('',$,(#3),.CURVE_3D.);", "curve_3d", 2),
        (
            "#1=SURFACE_CURVE('',#2,#3,.CURVE_3D.);",
            "associated_geometry",
            3,
        ),
        (
            "#1=SURFACE_CURVE('',#2,(#3),3);",
            "master_representation",
            4,
        ),
        ("#1=PCURVE('',1,#3);", "basis_surface", 2),
        ("#1=PCURVE('',#2,'x');", "reference_to_curve", 3),
        ("#1=DEFINITIONAL_REPRESENTATION('',#2,#3);", "items", 2),
        (
            "#1=DEFINITIONAL_REPRESENTATION('',(#2),$);",
            "context_of_items",
            3,
        ),
        ("#1=PLANE('',1.);", "position", 2),
        ("#1=CYLINDRICAL_SURFACE('',$,4.);", "position", 2),
        ("#1=CYLINDRICAL_SURFACE('',#2,$);", "radius", 3),
        ("#1=CONICAL_SURFACE('',#2,'r',0.5);", "radius", 3),
        ("#1=CONICAL_SURFACE('',#2,4.,#9);", "semi_angle", 4),
        ("#1=SPHERICAL_SURFACE('',#2,.T.);", "radius", 3),
        ("#1=TOROIDAL_SURFACE('',#2,$,2.);", "major_radius", 3),
        ("#1=TOROIDAL_SURFACE('',#2,10.,'2');", "minor_radius", 4),
        (
            "#1=DEGENERATE_TOROIDAL_SURFACE('',#2,1.,2.,1);",
            "select_outer",
            5,
        ),
        (
            "#1=SURFACE_OF_LINEAR_EXTRUSION('',2.,#3);",
            "swept_curve",
            2,
        ),
        (
            "#1=SURFACE_OF_LINEAR_EXTRUSION('',#2,$);",
            "extrusion_axis",
            3,
        ),
        ("#1=SURFACE_OF_REVOLUTION('',#2,(#3));", "axis_position", 3),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',$,0.,1.,0.,1.,.T.,.T.);",
            "basis_surface",
            2,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,'0',1.,0.,1.,.T.,.T.);",
            "u1",
            3,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,#1,0.,1.,.T.,.T.);",
            "u2",
            4,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,1.,$,1.,.T.,.T.);",
            "v1",
            5,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,1.,0.,.T.,.T.,.T.);",
            "v2",
            6,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,1.,0.,1.,.U.,.T.);",
            "usense",
            7,
        ),
        (
            "#1=RECTANGULAR_TRIMMED_SURFACE('',#2,0.,1.,0.,1.,.T.,1.);",
            "vsense",
            8,
        ),
        ("#1=VERTEX_POINT('',$);", "vertex_geometry", 2),
        ("#1=EDGE_CURVE('',1,#3,#4,.T.);", "edge_start", 2),
        ("#1=EDGE_CURVE('',#2,$,#4,.T.);", "edge_end", 3),
        ("#1=EDGE_CURVE('',#2,#3,*,.T.);", "edge_geometry", 4),
        ("#1=EDGE_CURVE('',#2,#3,#4,'T');", "same_sense", 5),
        ("#1=ORIENTED_EDGE('',*,*,$,.T.);", "edge_element", 4),
        ("#1=ORIENTED_EDGE('',*,*,#4,#5);", "orientation", 5),
        ("#1=EDGE_LOOP('',#2);", "edge_list", 2),
        ("#1=FACE_BOUND('',(#2),.T.);", "bound", 2),
        ("#1=FACE_OUTER_BOUND('',#2,.U.);", "orientation", 3),
        ("#1=ADVANCED_FACE('',#2,#4,.T.);", "bounds", 2),
        ("#1=ADVANCED_FACE('',(#2),1.,.T.);", "face_geometry", 3),
        ("#1=FACE_SURFACE('',(#2),#4,$);", "same_sense", 4),
    ];
    for &(text, attribute, position) in cases {
        let e = schema_error(text);
        assert_eq!(e.attribute, Some((position, attribute)), "{text}: {e:?}");
        assert_eq!((e.entity, e.line), (1, 5), "{text}");
    }
}

#[test]
fn wrong_parameter_counts_are_located() {
    for text in [
        "#1=CIRCLE('',#2);",
        "#1=LINE('',#2,#3,#4);",
        "#1=AXIS2_PLACEMENT_3D('',#2,$);",
        "#1=EDGE_CURVE('',#2,#3,#4);",
    ] {
        let e = schema_error(text);
        assert!(e.message.starts_with("expected "), "{text}: {}", e.message);
        assert_eq!(e.line, 5);
    }
}

/// The fast rejections of `is_geometry_entity` never turn away an entity of the table.
#[test]
fn geometry_entity_names() {
    for name in GEOMETRY_ENTITIES {
        assert!(is_geometry_entity(name), "{name}");
    }
    for other in [
        "CARTESIAN_POINT",
        "B_SPLINE_CURVE_WITH_KNOTS",
        "B_SPLINE_SURFACE_WITH_KNOTS",
        "BREP_WITH_VOIDS_X",
        "",
        "line",
        "_X",
        "PRODUCT",
        // Names of an entry's length that differ from it in one letter.
        "AXIS2_PLACEMENT_3E",
        "LINF",
        "PLANF",
        "VERTEX_POINS",
    ] {
        assert!(!is_geometry_entity(other), "{other}");
        assert_eq!(GeometryEntity::named(other), None, "{other}");
        assert_eq!(GeometryEntity::in_table(other), None, "{other}");
    }
}

/// A `GeometryEntity` names the table entry it was made from: every entry, found by its
/// name through the grouped table, by the compile-time search and through the decoders, is
/// itself again; distinct entries are distinct values.
#[test]
fn geometry_entities_are_their_table_entries() {
    let mut seen = std::collections::HashSet::new();
    for name in GEOMETRY_ENTITIES {
        let e = GeometryEntity::named(name).expect("in the table");
        assert_eq!(e.name(), *name);
        assert_eq!(e, *name);
        assert_eq!(e.to_string(), *name);
        // The compile-time search agrees with the grouped table.
        assert_eq!(GeometryEntity::in_table(name), Some(e));
        assert!(seen.insert(e), "{name} twice");
    }
    assert_eq!(known_entity!("SEAM_CURVE").name(), "SEAM_CURVE");
    // The one-pass reader (a simple instance) and the general path (a complex one) give
    // the table's entry.
    let circle = GeometryEntity::named("CIRCLE").expect("in the table");
    for text in [
        "#1=CIRCLE('c',#2,5.);",
        "#1=( CURVE() GEOMETRIC_REPRESENTATION_ITEM() CIRCLE(5.) CONIC(#2) REPRESENTATION_ITEM('c') );",
    ] {
        assert_eq!(item(text).unwrap().unwrap().entity, circle, "{text}");
    }
}
