//! The commonest geometry and topology instances of a B-rep (ISO 10303-42: direction,
//! vector, the placements, line, circle, ellipse, the elementary surfaces, surface_curve,
//! seam_curve, pcurve, definitional_representation (ISO 10303-43), vertex_point,
//! edge_curve, oriented_edge, edge_loop, face_bound, face_outer_bound, advanced_face,
//! face_surface, open_shell, closed_shell, manifold_solid_brep), read from the body text of
//! a simple instance in one pass into a [`GeometryItem`].
//!
//! Private to [`Scanned::geometry_item`](super::Scanned::geometry_item), the one decoder of
//! these records: its general path (the grammar, then the attribute tables) builds a
//! [`Parameter`](super::Parameter) tree and a table of named slots for every instance, most
//! of the cost of reading a B-rep whose instances are a few references each. The reader here
//! follows the attribute order of each entity's supertype chain (`SUPERTYPE_CHAINS` in the
//! schema module; ISO 10303-21 clause 12.2 syntax): the `name` string first, then the
//! attributes, each a reference, an optional reference (`$`), a REAL, a BOOLEAN, an
//! enumeration, a derived `*` (ORIENTED_EDGE's `edge_start` and `edge_end`) or a list of
//! references or of REALs.
//!
//! Exactness: the reader succeeds only where the general path gives an equal item (record,
//! name, entity, entity type): the keyword written in full (not a short name), every token
//! as the grammar reads it ([`Reader`]), the parameter count and nesting within the limits.
//! Anything else (a complex instance, an INTEGER where a REAL is expected, a typed value, a
//! comment, `$` where a value is required, `.U.` for a BOOLEAN, an attribute too many or too
//! few) gives `None`, and the caller takes the general path, which reads it or reports the
//! located error. The tests compare both paths on every repository STEP file and on damaged
//! copies of their instances.

use super::geometry::{GeometryEntity, GeometryItem, GeometryRecord, Ratios, Refs, known_entity};
use super::grammar::ParamLimits;
use super::instance_text::Reader;
use super::scan::RawInstance;
use super::string::StepString;

/// Reads `raw` if it is a simple instance of one of the entities listed in the module
/// documentation, in the usual form; `None` means "not read here" (see there).
///
/// `limits` must be the limits the instance was scanned with.
pub(crate) fn read<'a>(
    text: &'a str,
    raw: &RawInstance<'a>,
    limits: ParamLimits,
) -> Option<GeometryItem<'a>> {
    let (entity, shape, mut r, name) = head(text, raw, limits)?;
    use GeometryRecord as R;
    let record = match shape {
        Shape::Direction => R::Direction {
            direction_ratios: r.next_ratios()?,
        },
        Shape::Vector => R::Vector {
            orientation: r.next_reference()?,
            magnitude: r.next_real()?,
        },
        Shape::Axis1 => R::Axis1Placement {
            location: r.next_reference()?,
            axis: r.next_optional_reference()?,
        },
        Shape::Axis2d => R::Axis2Placement2d {
            location: r.next_reference()?,
            ref_direction: r.next_optional_reference()?,
        },
        Shape::Axis3d => R::Axis2Placement3d {
            location: r.next_reference()?,
            axis: r.next_optional_reference()?,
            ref_direction: r.next_optional_reference()?,
        },
        Shape::Line => R::Line {
            pnt: r.next_reference()?,
            dir: r.next_reference()?,
        },
        Shape::Circle => R::Circle {
            position: r.next_reference()?,
            radius: r.next_real()?,
        },
        Shape::Ellipse => R::Ellipse {
            position: r.next_reference()?,
            semi_axis_1: r.next_real()?,
            semi_axis_2: r.next_real()?,
        },
        Shape::Plane => R::Plane {
            position: r.next_reference()?,
        },
        Shape::Cylinder => R::CylindricalSurface {
            position: r.next_reference()?,
            radius: r.next_real()?,
        },
        Shape::Cone => R::ConicalSurface {
            position: r.next_reference()?,
            radius: r.next_real()?,
            semi_angle: r.next_real()?,
        },
        Shape::Sphere => R::SphericalSurface {
            position: r.next_reference()?,
            radius: r.next_real()?,
        },
        Shape::Torus => R::ToroidalSurface {
            position: r.next_reference()?,
            major_radius: r.next_real()?,
            minor_radius: r.next_real()?,
            select_outer: None,
        },
        Shape::SurfaceCurve => R::SurfaceCurve {
            curve_3d: r.next_reference()?,
            associated_geometry: r.next_references()?.into_vec().into_boxed_slice(),
            master_representation: {
                r.byte(b',')?;
                r.enumeration()?
            },
        },
        Shape::Pcurve => R::Pcurve {
            basis_surface: r.next_reference()?,
            reference_to_curve: r.next_reference()?,
        },
        Shape::DefinitionalRepresentation => R::DefinitionalRepresentation {
            items: r.next_references()?,
            context_of_items: r.next_reference()?,
        },
        Shape::VertexPoint => R::VertexPoint {
            vertex_geometry: r.next_reference()?,
        },
        Shape::EdgeCurve => R::EdgeCurve {
            edge_start: r.next_reference()?,
            edge_end: r.next_reference()?,
            edge_geometry: r.next_reference()?,
            same_sense: r.next_boolean()?,
        },
        Shape::OrientedEdge => {
            // `edge_start` and `edge_end` are derived (ISO 10303-42 oriented_edge).
            r.next_derived()?;
            r.next_derived()?;
            R::OrientedEdge {
                edge_element: r.next_reference()?,
                orientation: r.next_boolean()?,
            }
        }
        Shape::EdgeLoop => R::EdgeLoop {
            edge_list: r.next_references()?.into_vec(),
        },
        Shape::FaceBound => R::FaceBound {
            bound: r.next_reference()?,
            orientation: r.next_boolean()?,
        },
        Shape::Face => R::FaceSurface {
            bounds: r.next_references()?,
            face_geometry: r.next_reference()?,
            same_sense: r.next_boolean()?,
        },
        Shape::Shell => R::Shell {
            cfs_faces: r.next_references()?.into_vec(),
            closed: entity == "CLOSED_SHELL",
        },
        Shape::Solid => R::ManifoldSolidBrep {
            outer: r.next_reference()?,
            voids: Vec::new(),
        },
    };
    r.byte(b')')?;
    r.ws();
    (r.i == r.b.len()).then(|| GeometryItem {
        name: Some(name),
        entity,
        entity_type: entity.name().into(),
        record,
    })
}

/// The start of every instance [`read`] reads, `KEYWORD('name'`: the entity, its attribute
/// layout, the reader after the name, and the name.
#[inline(always)]
fn head<'a>(
    text: &'a str,
    raw: &RawInstance<'a>,
    limits: ParamLimits,
) -> Option<(GeometryEntity, Shape, Reader<'a>, StepString<'a>)> {
    let keyword = raw.keyword(text)?;
    let (entity, shape) = shape_of(keyword)?;
    let mut r = Reader::new(text, raw, limits);
    r.i = keyword.len();
    r.byte(b'(')?;
    let name = r.string()?;
    Some((entity, shape, r, name))
}

/// The entity type and the name [`read`] gives `raw`, read from its start alone: for an
/// instance `read` read before (the rest of it is as it was then). `None` where `read`'s
/// start is not met (see there).
pub(crate) fn name<'a>(
    text: &'a str,
    raw: &RawInstance<'a>,
    limits: ParamLimits,
) -> Option<(&'static str, StepString<'a>)> {
    head(text, raw, limits).map(|(entity, _, _, name)| (entity.name(), name))
}

/// The attribute layouts read here (one per record shape).
#[derive(Clone, Copy)]
enum Shape {
    Direction,
    Vector,
    Axis1,
    Axis2d,
    Axis3d,
    Line,
    Circle,
    Ellipse,
    Plane,
    Cylinder,
    Cone,
    Sphere,
    Torus,
    SurfaceCurve,
    Pcurve,
    DefinitionalRepresentation,
    VertexPoint,
    EdgeCurve,
    OrientedEdge,
    EdgeLoop,
    FaceBound,
    Face,
    Shell,
    Solid,
}

/// The entity (as [`GEOMETRY_ENTITIES`](super::geometry::GEOMETRY_ENTITIES) names it) and
/// the layout of a keyword read here.
fn shape_of(keyword: &str) -> Option<(GeometryEntity, Shape)> {
    use Shape as S;
    Some(match keyword {
        "DIRECTION" => (known_entity!("DIRECTION"), S::Direction),
        "VECTOR" => (known_entity!("VECTOR"), S::Vector),
        "AXIS1_PLACEMENT" => (known_entity!("AXIS1_PLACEMENT"), S::Axis1),
        "AXIS2_PLACEMENT_2D" => (known_entity!("AXIS2_PLACEMENT_2D"), S::Axis2d),
        "AXIS2_PLACEMENT_3D" => (known_entity!("AXIS2_PLACEMENT_3D"), S::Axis3d),
        "LINE" => (known_entity!("LINE"), S::Line),
        "CIRCLE" => (known_entity!("CIRCLE"), S::Circle),
        "ELLIPSE" => (known_entity!("ELLIPSE"), S::Ellipse),
        "PLANE" => (known_entity!("PLANE"), S::Plane),
        "CYLINDRICAL_SURFACE" => (known_entity!("CYLINDRICAL_SURFACE"), S::Cylinder),
        "CONICAL_SURFACE" => (known_entity!("CONICAL_SURFACE"), S::Cone),
        "SPHERICAL_SURFACE" => (known_entity!("SPHERICAL_SURFACE"), S::Sphere),
        "TOROIDAL_SURFACE" => (known_entity!("TOROIDAL_SURFACE"), S::Torus),
        "SURFACE_CURVE" => (known_entity!("SURFACE_CURVE"), S::SurfaceCurve),
        "SEAM_CURVE" => (known_entity!("SEAM_CURVE"), S::SurfaceCurve),
        "PCURVE" => (known_entity!("PCURVE"), S::Pcurve),
        "DEFINITIONAL_REPRESENTATION" => (
            known_entity!("DEFINITIONAL_REPRESENTATION"),
            S::DefinitionalRepresentation,
        ),
        "VERTEX_POINT" => (known_entity!("VERTEX_POINT"), S::VertexPoint),
        "EDGE_CURVE" => (known_entity!("EDGE_CURVE"), S::EdgeCurve),
        "ORIENTED_EDGE" => (known_entity!("ORIENTED_EDGE"), S::OrientedEdge),
        "EDGE_LOOP" => (known_entity!("EDGE_LOOP"), S::EdgeLoop),
        "FACE_BOUND" => (known_entity!("FACE_BOUND"), S::FaceBound),
        "FACE_OUTER_BOUND" => (known_entity!("FACE_OUTER_BOUND"), S::FaceBound),
        "ADVANCED_FACE" => (known_entity!("ADVANCED_FACE"), S::Face),
        "FACE_SURFACE" => (known_entity!("FACE_SURFACE"), S::Face),
        "OPEN_SHELL" => (known_entity!("OPEN_SHELL"), S::Shell),
        "CLOSED_SHELL" => (known_entity!("CLOSED_SHELL"), S::Shell),
        "MANIFOLD_SOLID_BREP" => (known_entity!("MANIFOLD_SOLID_BREP"), S::Solid),
        _ => return None,
    })
}

impl Reader<'_> {
    /// `,` then a reference.
    fn next_reference(&mut self) -> Option<u64> {
        self.byte(b',')?;
        self.ws();
        self.param()?;
        self.reference_token()
    }

    /// `,` then a reference or `$`.
    fn next_optional_reference(&mut self) -> Option<Option<u64>> {
        self.byte(b',')?;
        self.ws();
        self.param()?;
        if self.b.get(self.i) == Some(&b'$') {
            self.i += 1;
            return Some(None);
        }
        self.reference_token().map(Some)
    }

    /// `,` then `*`.
    fn next_derived(&mut self) -> Option<()> {
        self.byte(b',')?;
        self.byte(b'*')?;
        self.param()
    }

    /// `,` then a REAL.
    fn next_real(&mut self) -> Option<f64> {
        self.byte(b',')?;
        self.ws();
        self.param()?;
        self.real_token()
    }

    /// `,` then `.T.` or `.F.`.
    fn next_boolean(&mut self) -> Option<bool> {
        self.byte(b',')?;
        match self.enumeration()? {
            "T" => Some(true),
            "F" => Some(false),
            _ => None,
        }
    }

    /// `,` then a list of references: held inline up to two (no allocation), else in one
    /// allocation of the counted length, which [`Refs::into_vec`] keeps for a vector.
    fn next_references(&mut self) -> Option<Refs> {
        self.byte(b',')?;
        let reserve = self.open_list(1, None)?;
        let mut refs = Refs::new();
        refs.reserve_exact(reserve);
        self.elements(Self::reference_token, |v| {
            refs.push(v);
            Some(())
        })?;
        Some(refs)
    }

    /// `,` then a DIRECTION's list of REALs, read without an allocation; `None` for more
    /// than three (the general path reports it) or any other shape.
    fn next_ratios(&mut self) -> Option<Ratios> {
        self.byte(b',')?;
        self.open_list(1, Some(3))?;
        let mut ratios = Ratios::default();
        self.elements(Self::real_token, |v| ratios.push(v))?;
        Some(ratios)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Limits;
    use crate::step::schema::At;
    use crate::step::test_files::{check_damaged, edit, file, repo_files};
    use crate::step::{Scanned, scan};
    use proptest::prelude::*;

    /// One statement of every kind read here, in the form Open CASCADE writes.
    const KINDS: &[&str] = &[
        "#9=DIRECTION('',(0.,-1.,1.E-17));",
        "#9=VECTOR('',#2,2.5);",
        "#9=AXIS1_PLACEMENT('',#2,$);",
        "#9=AXIS2_PLACEMENT_2D('',#2,#3);",
        "#9=AXIS2_PLACEMENT_3D('',#2,#3,#4);",
        "#9=AXIS2_PLACEMENT_3D('',#2,$,$);",
        "#9=LINE('',#2,#3);",
        "#9=CIRCLE('',#2,5.);",
        "#9=ELLIPSE('',#2,5.,2.5);",
        "#9=PLANE('',#2);",
        "#9=CYLINDRICAL_SURFACE('',#2,5.);",
        "#9=CONICAL_SURFACE('',#2,5.,0.785398163397);",
        "#9=SPHERICAL_SURFACE('',#2,5.);",
        "#9=TOROIDAL_SURFACE('',#2,5.,1.);",
        "#9=SURFACE_CURVE('',#2,(#3,#4),.PCURVE_S1.);",
        "#9=SEAM_CURVE('',#2,(#3,#4),.PCURVE_S1.);",
        "#9=PCURVE('',#2,#3);",
        "#9=DEFINITIONAL_REPRESENTATION('',(#2),#3);",
        "#9=VERTEX_POINT('',#2);",
        "#9=EDGE_CURVE('',#2,#3,#4,.T.);",
        "#9=ORIENTED_EDGE('',*,*,#2,.F.);",
        "#9=EDGE_LOOP('',(#2,#3,#4));",
        "#9=FACE_BOUND('',#2,.T.);",
        "#9=FACE_OUTER_BOUND('',#2,.T.);",
        "#9=ADVANCED_FACE('',(#2,#3),#4,.F.);",
        "#9=FACE_SURFACE('',(#2),#4,.T.);",
        "#9=OPEN_SHELL('',(#2,#3));",
        "#9=CLOSED_SHELL('',(#2,#3,#4));",
        "#9=MANIFOLD_SOLID_BREP('a \\X\\E9 ''b''',#2);",
    ];

    /// The contract: when the text reader answers, the general path (the grammar, then
    /// [`GeometryItem::from_instance`]) gives an equal item (reals compared bit for bit
    /// through `Debug`, which keeps `-0.0`). Returns whether the text reader answered.
    fn check(s: &Scanned<'_>, raw: &RawInstance<'_>, limits: &Limits) -> bool {
        let Some(direct) = read(s.text, raw, ParamLimits::from(limits)) else {
            return false;
        };
        let inst = match s.decode(raw) {
            Ok(i) => i,
            Err(e) => panic!("direct read #{} but general decode fails: {e}", raw.id),
        };
        match GeometryItem::from_instance(&inst, At::default()) {
            Ok(Some(g)) => {
                assert_eq!(direct, g, "#{}: {}", raw.id, raw.body(s.text));
                assert_eq!(format!("{direct:?}"), format!("{g:?}"), "#{}", raw.id);
            }
            other => panic!(
                "direct read #{} but the general path gives {other:?}",
                raw.id
            ),
        }
        true
    }

    /// Checks every instance of a file; returns (answered, simple instances of the kinds
    /// read here that the general path reads).
    fn check_text(text: &str, limits: &Limits) -> (usize, usize) {
        let Ok(s) = scan(text, limits) else {
            return (0, 0);
        };
        let mut answered = 0;
        let mut readable = 0;
        for raw in &s.instances {
            if check(&s, raw, limits) {
                answered += 1;
            }
            let kind = raw.keyword(s.text).and_then(shape_of).is_some();
            let general = s.decode(raw).is_ok_and(|inst| {
                GeometryItem::from_instance(&inst, At::default()).is_ok_and(|i| i.is_some())
            });
            readable += usize::from(kind && general);
            // The provenance read from the instance's start is the decoded item's.
            if let Ok(Some(item)) = s.geometry_item(raw) {
                let provenance = s.geometry_provenance(raw).map_err(|e| e.to_string());
                assert_eq!(
                    provenance,
                    Ok(Some((item.entity_type, item.name))),
                    "#{}: {}",
                    raw.id,
                    raw.body(s.text)
                );
            }
        }
        (answered, readable)
    }

    fn answers(data: &str, limits: &Limits) -> bool {
        let text: &'static str = Box::leak(file(data).into_boxed_str());
        let s = scan(text, limits).unwrap();
        let raw = s.instances.last().unwrap();
        check(&s, raw, limits)
    }

    #[test]
    fn every_kind_is_read_directly_and_agrees() {
        for stmt in KINDS {
            assert!(answers(stmt, &Limits::default()), "{stmt}");
        }
    }

    #[test]
    fn every_repository_file_agrees_and_freecad_b_reps_are_read_directly() {
        let files = repo_files();
        assert!(files.len() > 50, "sample files not found");
        let mut total = 0;
        for (path, text) in &files {
            let (answered, readable) = check_text(text, &Limits::default());
            total += answered;
            // Open CASCADE writes only the shapes read directly.
            if path.to_string_lossy().contains("samples/freecad") {
                assert_eq!(answered, readable, "{}", path.display());
            }
        }
        assert!(total > 5_000, "only {total} direct reads");
    }

    #[test]
    fn declined_shapes() {
        let d = Limits::default();
        for stmt in [
            // A short name, a complex instance, a comment, a typed or integer value, `$`
            // where a value is required, `.U.` for a BOOLEAN, `#` for a derived attribute.
            "#9=CIRCLE('',#2,5);",
            "#9=CIRCLE('',#2,POSITIVE_LENGTH_MEASURE(5.));",
            "#9=CIRCLE('',#2 /* r */,5.);",
            "#9=CIRCLE('',$,5.);",
            "#9=VERTEX_POINT($,#2);",
            "#9=EDGE_CURVE('',#2,#3,#4,.U.);",
            "#9=ORIENTED_EDGE('',#5,#6,#2,.F.);",
            "#9=( GEOMETRIC_REPRESENTATION_ITEM() PLANE(#2) REPRESENTATION_ITEM('') SURFACE() ELEMENTARY_SURFACE(#2) );",
            // One attribute too many or too few, an empty element, bad tokens.
            "#9=PLANE('',#2,#3);",
            "#9=LINE('',#2);",
            "#9=EDGE_LOOP('',(#2,));",
            "#9=DIRECTION('',(1.,0.5.2));",
            "#9=VECTOR('',#2,1.5E3X);",
            "#9=VECTOR('',#2A,1.5);",
        ] {
            assert!(!answers(stmt, &d), "{stmt}");
        }
        // Blanks the grammar skips are still read.
        assert!(answers(
            "#9 = ADVANCED_FACE ( '' , ( #2 ,\r\n #3 ) , #4 , .F. ) ;",
            &d
        ));
        // Limits: a list needs nesting depth 2; every scalar and list is a parameter.
        let at = |max_params, max_depth| Limits {
            max_params_per_entity: max_params,
            max_nesting_depth: max_depth,
            ..Limits::default()
        };
        assert!(answers("#9=EDGE_LOOP('',(#2,#3));", &at(4, 2)));
        assert!(!answers("#9=EDGE_LOOP('',(#2,#3));", &at(3, 2)));
        assert!(!answers("#9=EDGE_LOOP('',(#2,#3));", &at(100, 1)));
        assert!(answers("#9=ORIENTED_EDGE('',*,*,#2,.F.);", &at(5, 1)));
        assert!(!answers("#9=ORIENTED_EDGE('',*,*,#2,.F.);", &at(4, 1)));
    }

    /// The geometry instances of the FreeCAD samples and [`KINDS`], as separate statements.
    fn sample_statements() -> &'static [String] {
        static CACHE: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
        CACHE.get_or_init(|| {
            let mut out: Vec<String> = KINDS.iter().map(|s| (*s).to_owned()).collect();
            for (path, text) in repo_files() {
                if !path.to_string_lossy().contains("samples/freecad/analytic") {
                    continue;
                }
                let Ok(s) = scan(&text, &Limits::default()) else {
                    continue;
                };
                for raw in &s.instances {
                    if read(&text, raw, ParamLimits::from(&Limits::default())).is_some() {
                        out.push(format!("#{}={};", raw.id, raw.body(&text)));
                    }
                }
            }
            out
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]
        /// Damaged copies of real instances: whenever the text reader answers, the general
        /// path agrees (checked inside `check_text`), under default and tight limits; nothing
        /// panics.
        #[test]
        fn damaged_instances_agree(
            pick in any::<prop::sample::Index>(),
            edits in prop::collection::vec(edit(), 0..4),
            max_params in 1usize..12,
            max_depth in 1usize..3,
        ) {
            let stmt: &String = pick.get(sample_statements());
            check_damaged(stmt, &edits, max_params, max_depth, check_text);
        }
    }
}
