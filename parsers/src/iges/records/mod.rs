//! The entity schema: one declaration per entity nurbsx reads (IGES 5.3 chapter 4), and
//! the typed records built from it.
//!
//! A [`Schema`] lists an entity's parameters in the order of its table in the standard,
//! with their types (section 2.2.2), which are DE pointers and to which entity types, and
//! how counts read earlier repeat later fields. One generic reader ([`read`]) decodes any
//! declared entity from the parameter grammar into [`Values`]; the record type then takes
//! its fields by name. The arity check (a record must hold what its counts declare, checked
//! before anything is allocated) and the pointer walk ([`Values::pointers`]) come from the
//! declaration too. Adding an entity is one declaration plus its record type.
//!
//! Four layouts no declaration can hold, because the type or the count of a parameter is
//! read from the record's own values or from another entity, have a checker each instead
//! ([`Dependent`], [`read_dependent`]) giving the same checks: the 406 forms 11 Tabular
//! Data (section 4.107) and 27 Generic Data (section 4.123), the 322 Attribute Table
//! Definition (section 4.79) and the 422 Attribute Table Instance (section 4.141).

mod analytic_surfaces190_198;
mod annotation202_230;
mod array_subfigure412_414;
mod associativity402;
mod attribute_table322;
mod attribute_table422;
mod bounded_surface143;
mod brep_solid186;
mod circular_arc100;
mod color314_line_font304;
mod composite102;
mod conic_arc104;
mod copious_data106;
mod curve126;
mod curve_on_surface142;
mod direction123;
mod edge_list504;
mod external_reference416;
mod face510;
mod line110;
mod loop508;
mod network_subfigure320_420;
mod nodal_constraint418;
mod plane108;
mod point116;
mod property406;
mod revolution120;
mod ruled_surface118;
mod shell514;
mod solid_instance430;
mod spline_curve112;
mod spline_surface114;
mod subfigure308_408;
mod surface128;
mod tabulated_cylinder122;
mod text_font310_template312;
mod transform124;
mod trimmed_surface144;
mod units316;
mod vertex_list502;
mod view410_drawing404;

pub use analytic_surfaces190_198::{Cone194, Cylinder192, PlaneSurface190, Sphere196, Torus198};
pub use associativity402::Group402;
pub use bounded_surface143::{Boundary141, BoundaryCurve, BoundedSurface143};
pub use brep_solid186::BrepSolid186;
pub use circular_arc100::CircularArc100;
pub use composite102::CompositeCurve102;
pub use conic_arc104::ConicArc104;
pub use copious_data106::CopiousData106;
pub use curve_on_surface142::CurveOnSurface142;
pub use curve126::Curve126;
pub use direction123::Direction123;
pub use edge_list504::{Edge, EdgeList504};
pub use face510::Face510;
pub use line110::Line110;
pub use loop508::{Loop508, LoopEdge};
pub use plane108::Plane108;
pub use point116::Point116;
pub use revolution120::Revolution120;
pub use ruled_surface118::RuledSurface118;
pub use shell514::Shell514;
pub use spline_curve112::SplineCurve112;
pub use spline_surface114::SplineSurface114;
pub use subfigure308_408::{SubfigureDefinition308, SubfigureInstance408};
pub use surface128::Surface128;
pub use tabulated_cylinder122::TabulatedCylinder122;
pub use transform124::Transform124;
pub use trimmed_surface144::TrimmedSurface144;
pub use vertex_list502::VertexList502;

use super::directory::DirectoryEntry;
use super::error::ErrorKind;
use super::grammar::parameters::{Error, ParameterReader};

/// The field name [`Values::pointers`] gives the associativity pointers of IGES 5.3 section
/// 2.2.4.5.2 (back pointers from a member to the 402 instances listing it).
pub const ASSOCIATIVITY_POINTER: &str = "associativity pointer";

/// Curve entities a curve pointer may name (IGES 5.3 sections 4.3-4.11, 4.13, 4.14, 4.16,
/// 4.23 and 4.25).
pub const CURVES: &[i64] = &[100, 102, 104, 106, 110, 112, 116, 126, 130];

/// Surface entities a surface pointer may name (IGES 5.3 sections 4.12, 4.15, 4.17-4.19,
/// 4.24, 4.30, 4.33 and 4.50-4.54).
pub const SURFACES: &[i64] = &[
    108, 114, 118, 120, 122, 128, 140, 143, 190, 192, 194, 196, 198,
];

/// Every declared entity whose parameters do not depend on the form.
///
/// Not declared here, because a parameter's type or count is read from the data: the 322
/// Attribute Table Definition (section 4.79, whose forms 1 and 2 hold values of the types
/// its own attribute entries name) and the 422 Attribute Table Instance (section 4.141,
/// whose values follow the layout of the 322 its DE structure field names). Each has its
/// own checker instead ([`Dependent`], [`read_dependent`]), with the same checks.
pub const SCHEMAS: &[Schema] = &[
    circular_arc100::SCHEMA,
    composite102::SCHEMA,
    conic_arc104::SCHEMA,
    copious_data106::SCHEMA,
    plane108::SCHEMA,
    line110::SCHEMA,
    spline_curve112::SCHEMA,
    spline_surface114::SCHEMA,
    point116::SCHEMA,
    ruled_surface118::SCHEMA,
    revolution120::SCHEMA,
    tabulated_cylinder122::SCHEMA,
    direction123::SCHEMA,
    transform124::SCHEMA,
    curve126::SCHEMA,
    surface128::SCHEMA,
    bounded_surface143::BOUNDARY_SCHEMA,
    curve_on_surface142::SCHEMA,
    bounded_surface143::SCHEMA,
    trimmed_surface144::SCHEMA,
    brep_solid186::SCHEMA,
    subfigure308_408::DEFINITION_SCHEMA,
    subfigure308_408::INSTANCE_SCHEMA,
    vertex_list502::SCHEMA,
    edge_list504::SCHEMA,
    loop508::SCHEMA,
    face510::SCHEMA,
    shell514::SCHEMA,
    analytic_surfaces190_198::PLANE_SCHEMA,
    analytic_surfaces190_198::CYLINDER_SCHEMA,
    analytic_surfaces190_198::CONE_SCHEMA,
    analytic_surfaces190_198::SPHERE_SCHEMA,
    analytic_surfaces190_198::TORUS_SCHEMA,
    annotation202_230::ANGULAR_DIMENSION,
    annotation202_230::DIAMETER_DIMENSION,
    annotation202_230::FLAG_NOTE,
    annotation202_230::GENERAL_LABEL,
    annotation202_230::GENERAL_NOTE,
    annotation202_230::LEADER_ARROW,
    annotation202_230::LINEAR_DIMENSION,
    annotation202_230::POINT_DIMENSION,
    annotation202_230::GENERAL_SYMBOL,
    annotation202_230::SECTIONED_AREA,
    annotation202_230::CURVE_DIMENSION,
    annotation202_230::NEW_GENERAL_NOTE,
    color314_line_font304::COLOR,
    text_font310_template312::TEXT_FONT,
    text_font310_template312::TEXT_TEMPLATE,
    units316::SCHEMA,
    network_subfigure320_420::DEFINITION,
    network_subfigure320_420::INSTANCE,
    array_subfigure412_414::RECTANGULAR_ARRAY,
    array_subfigure412_414::CIRCULAR_ARRAY,
    nodal_constraint418::SCHEMA,
    solid_instance430::SCHEMA,
];

/// Declarations whose parameters depend on the form number: `(forms, schema)`.
/// The 402 Associativity Instance forms 1, 3-5, 7, 9, 12-16 and 18-21 (every form IGES 5.3
/// predefines, sections 4.81-4.95), the 406 Property forms 1-3, 5-10, 12-26 and 28-36, the
/// two forms each of 218, 222, 304, 404 and 410, and the five forms of 416. The 406 forms
/// 11 (Tabular Data, section 4.107: its value counts are sums and products of values it
/// lists) and 27 (Generic Data, section 4.123: each value's type is the integer before
/// it) are not declared: each has its own checker ([`Dependent`]). Implementor-defined
/// forms (5001-9999) are not declared: their parameters and pointers are unchecked.
pub const FORM_SCHEMAS: &[(&[i64], Schema)] = &[
    (&[1, 7, 14, 15], associativity402::GROUP),
    (&[3], associativity402::VIEWS_VISIBLE),
    (&[4], associativity402::VIEWS_VISIBLE_WITH_ATTRIBUTES),
    (&[5], associativity402::LABEL_DISPLAY),
    (&[9], associativity402::SINGLE_PARENT),
    (&[12], associativity402::EXTERNAL_REFERENCE_INDEX),
    (&[13], associativity402::DIMENSIONED_GEOMETRY),
    (&[16], associativity402::PLANAR),
    (&[18], associativity402::FLOW),
    (&[19], associativity402::SEGMENTED_VIEWS_VISIBLE),
    (&[20], associativity402::PIPING_FLOW),
    (&[21], associativity402::NEW_DIMENSIONED_GEOMETRY),
    (&[1], property406::DEFINITION_LEVELS),
    (&[15], property406::NAME),
    (&[2], property406::REGION_RESTRICTION),
    (&[3], property406::LEVEL_FUNCTION),
    (&[5], property406::LINE_WIDENING),
    (&[16], property406::DRAWING_SIZE),
    (&[17], property406::DRAWING_UNITS),
    (&[18], property406::INTERCHARACTER_SPACING),
    (&[19], property406::LINE_FONT_PATTERN),
    (&[20], property406::HIGHLIGHT),
    (&[21], property406::PICK),
    (&[23], property406::ASSOCIATIVITY_GROUP_TYPE),
    (&[28], property406::DIMENSION_UNITS),
    (&[29], property406::DIMENSION_TOLERANCE),
    (&[30], property406::DIMENSION_DISPLAY_DATA),
    (&[6], property406::DRILLED_HOLE),
    (&[7], property406::REFERENCE_DESIGNATOR),
    (&[8], property406::PIN_NUMBER),
    (&[9], property406::PART_NUMBER),
    (&[10], property406::HIERARCHY),
    (&[12], property406::EXTERNAL_REFERENCE_FILE_LIST),
    (&[13], property406::NOMINAL_SIZE),
    (&[14], property406::FLOW_LINE_SPECIFICATION),
    (&[22], property406::UNIFORM_RECTANGULAR_GRID),
    (&[24], property406::LEVEL_TO_LEP_LAYER_MAP),
    (&[25], property406::LEP_ARTWORK_STACKUP),
    (&[26], property406::LEP_DRILLED_HOLE),
    (&[31], property406::BASIC_DIMENSION),
    (&[32], property406::DRAWING_SHEET_APPROVAL),
    (&[33], property406::DRAWING_SHEET_ID),
    (&[34], property406::UNDERSCORE),
    (&[35], property406::OVERSCORE),
    (&[36], property406::CLOSURE),
    (&[0], annotation202_230::ORDINATE_DIMENSION),
    (&[1], annotation202_230::ORDINATE_DIMENSION_WITH_LEADER),
    (&[0], annotation202_230::RADIUS_DIMENSION),
    (&[1], annotation202_230::RADIUS_DIMENSION_TWO_LEADERS),
    (&[1], color314_line_font304::LINE_FONT_TEMPLATE),
    (&[2], color314_line_font304::LINE_FONT_PATTERN),
    (&[0], view410_drawing404::DRAWING),
    (&[1], view410_drawing404::DRAWING_WITH_ROTATION),
    (&[0], view410_drawing404::VIEW_SCHEMA),
    (&[1], view410_drawing404::PERSPECTIVE_VIEW),
    (&[0, 2], external_reference416::FILE_AND_NAME),
    (&[1], external_reference416::FILE),
    (&[3], external_reference416::NAME),
    (&[4], external_reference416::LIBRARY_AND_NAME),
];

/// The declaration of entity type `entity` in form `form`: from [`SCHEMAS`], or for the
/// types whose parameters depend on the form, from [`FORM_SCHEMAS`].
pub fn schema_of(entity: i64, form: i64) -> Option<&'static Schema> {
    SCHEMAS.iter().find(|s| s.entity == entity).or_else(|| {
        FORM_SCHEMAS
            .iter()
            .find(|(forms, s)| s.entity == entity && forms.contains(&form))
            .map(|(_, s)| s)
    })
}

/// An entity whose parameter layout no [`Schema`] can declare, because the type or the
/// count of its parameters is read from its own values or from another entity; each has
/// its own checker in its record module, with the checks the declared entities get: the
/// parameter count against the counts and types it declares (too few: a
/// [`ErrorKind::Truncated`] error; too many: an [`ErrorKind::Arity`] error, as
/// [`read`] gives), each value of its declared type, and its DE pointers for
/// [`Values::pointers`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dependent {
    /// 406 form 11, Tabular Data (IGES 5.3 section 4.107).
    TabularData,
    /// 406 form 27, Generic Data (IGES 5.3 section 4.123).
    GenericData,
    /// 322 Attribute Table Definition in this form, 0 to 2 (IGES 5.3 section 4.79).
    AttributeDefinition(i64),
    /// 422 Attribute Table Instance in this form, 0 or 1 (IGES 5.3 section 4.141): its
    /// values follow the layout ([`attribute_layout`]) of the 322 its DE structure field
    /// names.
    AttributeInstance(i64),
}

/// The checker of entity type `entity` in form `form` when no [`Schema`] declares it.
pub fn dependent_of(entity: i64, form: i64) -> Option<Dependent> {
    match (entity, form) {
        (406, 11) => Some(Dependent::TabularData),
        (406, 27) => Some(Dependent::GenericData),
        (322, 0..=2) => Some(Dependent::AttributeDefinition(form)),
        (422, 0 | 1) => Some(Dependent::AttributeInstance(form)),
        _ => None,
    }
}

/// The layout of a 322 Attribute Table Definition's attributes that hold values, as a 422
/// Attribute Table Instance repeats them: `(AVT, AVC)` per attribute whose value count
/// `AVC` is not 0, in order (IGES 5.3 sections 4.79 and 4.141).
pub type AttributeLayout = Vec<(i64, usize)>;

/// Reads the parameters after the entity type of an entity of layout `dependent`, then
/// the associativity and property pointer groups (section 2.2.4.5.2), as [`read`] does
/// for a declared one; `layout` is the layout of the 322 a 422 follows (unused for the
/// others). The values' DE pointers come out of [`Values::pointers`]: the pointer values
/// (type code 4), and the 312 Text Display Template pointers of a 322 form 2.
pub fn read_dependent<'a>(
    dependent: Dependent,
    r: &mut ParameterReader<'a>,
    layout: &[(i64, usize)],
) -> Result<Values<'a>, Error<'a>> {
    let mut pointers = Vec::new();
    let mut templates = Vec::new();
    match dependent {
        Dependent::TabularData => property406::tabular_data(r)?,
        Dependent::GenericData => property406::generic_data(r, &mut pointers)?,
        Dependent::AttributeDefinition(form) => {
            attribute_table322::definition(r, form, &mut pointers, &mut templates)?;
        }
        Dependent::AttributeInstance(form) => {
            attribute_table422::instance(r, form, layout, &mut pointers)?;
        }
    }
    let mut values = Values {
        fields: DATA_POINTERS,
        values: vec![Value::Ints(pointers), Value::Ints(templates)],
        extra: 0,
        additional: Vec::new(),
        associativities: 0,
    };
    let start = r.index();
    values.associativities = additional_pointers(r, &mut values.additional)?;
    values.extra = r.index() - start;
    Ok(values)
}

/// Reads a 322 Attribute Table Definition (any form) for the layout a 422 follows.
pub fn attribute_layout<'a>(
    r: &mut ParameterReader<'a>,
    form: i64,
) -> Result<AttributeLayout, Error<'a>> {
    attribute_table322::definition(r, form, &mut Vec::new(), &mut Vec::new())
}

/// The pointer fields of the [`Dependent`] layouts, for [`Values::pointers`] (their counts
/// are never evaluated: the values are read by the checkers).
const DATA_POINTERS: &[Field] = &[
    Field::times("value", Type::Pointer(&[]), Count::Field("pointer values")),
    Field::times(
        "text display template",
        Type::Pointer(&[312]),
        Count::Field("AVC"),
    ),
];

/// The value types the type codes of the 406 form 27 Generic Data (IGES 5.3 section
/// 4.123) and the 322 Attribute Table Definition (section 4.79, `AVT`) name: 0 no value,
/// 1 integer, 2 real, 3 string, 4 pointer, 5 not used, 6 logical.
const VALUE_TYPES: std::ops::RangeInclusive<i64> = 0..=6;

/// Reads a type code (`TYPE`, `AVT`): an integer of [`VALUE_TYPES`].
fn value_type<'a>(r: &mut ParameterReader<'a>, name: &'static str) -> Result<i64, Error<'a>> {
    let at = r.rest();
    let code = r.integer(name, Some(0))?;
    if VALUE_TYPES.contains(&code) {
        Ok(code)
    } else {
        Err(Error::format(
            trim(at),
            ErrorKind::OutOfRange(format!(
                "{name} = {code} is no value type code (0 none, 1 integer, 2 real, 3 string, \
                 4 pointer, 5 not used, 6 logical)"
            )),
        ))
    }
}

/// Reads one value of type code `code` ([`VALUE_TYPES`]): a pointer goes to `pointers`
/// (0, no entity, left out); a logical is 0 (false) or 1 (true); the slot of "no value"
/// and "not used" is one parameter of any type.
fn typed_value<'a>(
    r: &mut ParameterReader<'a>,
    code: i64,
    name: &'static str,
    pointers: &mut Vec<i64>,
) -> Result<(), Error<'a>> {
    match code {
        1 => {
            r.integer(name, Some(0))?;
        }
        2 => {
            r.real(name)?;
        }
        3 => {
            r.string(name)?;
        }
        4 => {
            let p = r.integer(name, Some(0))?;
            if p != 0 {
                pointers.push(p);
            }
        }
        6 => {
            let at = r.rest();
            let v = r.integer(name, Some(0))?;
            if !matches!(v, 0 | 1) {
                return Err(Error::format(
                    trim(at),
                    ErrorKind::OutOfRange(format!(
                        "{name} = {v}, but a logical value is 0 (false) or 1 (true)"
                    )),
                ));
            }
        }
        _ => {
            if r.done() {
                // Past the record's end: the reader's error (a truncated record).
                r.integer(name, Some(0))?;
            } else {
                r.parameter()?;
            }
        }
    }
    Ok(())
}

/// Reads a count: an integer (`default` when defaulted; `None`: required), not negative.
fn count_parameter<'a>(
    r: &mut ParameterReader<'a>,
    name: &'static str,
    default: Option<i64>,
) -> Result<usize, Error<'a>> {
    let at = r.rest();
    let v = r.integer(name, default)?;
    usize::try_from(v).map_err(|_| {
        Error::format(
            trim(at),
            ErrorKind::OutOfRange(format!("{name} = {v} is negative")),
        )
    })
}

/// A count computed from the record's counts that overflows: an error at `at`.
#[cold]
fn too_big<'a>(at: &'a [u8], what: &str) -> Error<'a> {
    Error::format(
        trim(at),
        ErrorKind::OutOfRange(format!("{what} is too large")),
    )
}

/// `at` without its leading blanks: where a parameter's text starts.
fn trim(at: &[u8]) -> &[u8] {
    let blanks = at.iter().take_while(|&&c| c == b' ').count();
    at.get(blanks..).unwrap_or(at)
}

/// The entity type numbers IGES 5.3 defines (chapter 4; 0 is the Null entity), besides the
/// ranges of [`is_defined_entity_type`].
const DEFINED_ENTITY_TYPES: &[i64] = &[
    0, 100, 102, 104, 106, 108, 110, 112, 114, 116, 118, 120, 122, 123, 124, 125, 126, 128, 130,
    132, 134, 136, 138, 140, 141, 142, 143, 144, 146, 148, 150, 152, 154, 156, 158, 160, 162, 164,
    168, 180, 182, 184, 186, 190, 192, 194, 196, 198, 202, 204, 206, 208, 210, 212, 213, 214, 216,
    218, 220, 222, 228, 230, 302, 304, 306, 308, 310, 312, 314, 316, 320, 322, 402, 404, 406, 408,
    410, 412, 414, 416, 418, 420, 422, 430, 502, 504, 508, 510, 514,
];

/// Whether `entity` is an entity type number IGES 5.3 defines (section 2.2.4.4.1): one of
/// chapter 4's, a macro instance (600-699, 10000-99999) or an implementor-defined entity
/// (5001-9999).
pub fn is_defined_entity_type(entity: i64) -> bool {
    DEFINED_ENTITY_TYPES.contains(&entity)
        || (600..=699).contains(&entity)
        || (5001..=9999).contains(&entity)
        || (10000..=99999).contains(&entity)
}

/// The form numbers chapter 4 defines for the entity types whose forms are checked
/// (DE field 15); other types' forms are not judged. The 228 forms 5001-9999 and the 402
/// and 406 forms 5001-9999 are implementor-defined (sections 4.67, 4.80 and 4.97).
///
/// Each entry is the form list (or DE field 15 range) of the type's section: 104 section
/// 4.5 (1 ellipse, 2 hyperbola, 3 parabola, and 0, the older form whose conic type is read
/// from the coefficients alone), 106 the form table of section 4.6 (forms 1-3 there, 11-13
/// section 4.7, 20-21 section 4.8, 31-38 section 4.9, 40 section 4.10, 63 section 4.11),
/// the annotation entities of sections 4.55-4.68 (202 Angular Dimension 4.55, 204 Curve
/// Dimension 4.56, 206 Diameter Dimension 4.57, 208 Flag Note 4.58, 210 General Label
/// 4.59, 213 New General Note 4.61, 220 Point Dimension 4.65: form 0; 212 General Note
/// 4.60: forms 0-8, the fraction forms 100-102 and 105; 214 Leader (Arrow) 4.62: the
/// arrowhead forms 1-12; 216 Linear Dimension 4.63: 0 undetermined, 1 diameter, 2 radius;
/// 218 Ordinate Dimension 4.64 and 222 Radius Dimension 4.66: forms 0 and 1; 228 General
/// Symbol 4.67: 0 general symbol, 1 datum feature, 2 datum target, 3 feature control
/// frame; 230 Sectioned Area 4.68: 0 standard and 1 inverted crosshatch), 304 section
/// 4.70, 310 section 4.74 (form 0), 312 section 4.75 (0 absolute and 1 incremental
/// corner), 314 section 4.76, 316 section 4.77, 320 section 4.78 (form 0), 322 section
/// 4.79 (forms 0-2), 404 section 4.96, 406 the form sections 4.98-4.132 (form 4 has none),
/// 410 sections 4.134 and 4.135, 412 section 4.136 and 414 section 4.137 (form 0), 416
/// section 4.138, 418 section 4.139 and 420 section 4.140 (form 0), 422 section 4.141
/// (forms 0 and 1), 430 section 4.142.
const DEFINED_FORMS: &[(i64, &[i64])] = &[
    (100, &[0]),
    (102, &[0]),
    (104, &[0, 1, 2, 3]),
    (
        106,
        &[
            1, 2, 3, 11, 12, 13, 20, 21, 31, 32, 33, 34, 35, 36, 37, 38, 40, 63,
        ],
    ),
    (108, &[-1, 0, 1]),
    (110, &[0, 1, 2]),
    (112, &[0]),
    (114, &[0]),
    (116, &[0]),
    (118, &[0, 1]),
    (120, &[0]),
    (122, &[0]),
    (123, &[0]),
    (124, &[0, 1, 10, 11, 12]),
    (126, &[0, 1, 2, 3, 4, 5]),
    (128, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]),
    (141, &[0]),
    (142, &[0]),
    (143, &[0]),
    (144, &[0]),
    (186, &[0]),
    (190, &[0, 1]),
    (192, &[0, 1]),
    (194, &[0, 1]),
    (196, &[0, 1]),
    (198, &[0, 1]),
    (202, &[0]),
    (204, &[0]),
    (206, &[0]),
    (208, &[0]),
    (210, &[0]),
    (212, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 100, 101, 102, 105]),
    (213, &[0]),
    (214, &[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]),
    (216, &[0, 1, 2]),
    (218, &[0, 1]),
    (220, &[0]),
    (222, &[0, 1]),
    (228, &[0, 1, 2, 3]),
    (230, &[0, 1]),
    (304, &[1, 2]),
    (308, &[0]),
    (310, &[0]),
    (312, &[0, 1]),
    (314, &[0]),
    (316, &[0]),
    (320, &[0]),
    (322, &[0, 1, 2]),
    (402, &[1, 3, 4, 5, 7, 9, 12, 13, 14, 15, 16, 18, 19, 20, 21]),
    (404, &[0, 1]),
    (
        406,
        &[
            1, 2, 3, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25,
            26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36,
        ],
    ),
    (408, &[0]),
    (410, &[0, 1]),
    (412, &[0]),
    (414, &[0]),
    (416, &[0, 1, 2, 3, 4]),
    (418, &[0]),
    (420, &[0]),
    (422, &[0, 1]),
    (430, &[0, 1]),
    (502, &[1]),
    (504, &[1]),
    (508, &[0, 1]),
    (510, &[1]),
    (514, &[1, 2]),
];

/// Whether `form` is a form number of `entity`; `None` when its forms are not checked.
pub fn is_defined_form(entity: i64, form: i64) -> Option<bool> {
    let (_, forms) = DEFINED_FORMS.iter().find(|(e, _)| *e == entity)?;
    let implementor = matches!(entity, 228 | 402 | 406) && (5001..=9999).contains(&form);
    Some(forms.contains(&form) || implementor)
}

/// The type of a parameter as a schema declares it (IGES 5.3 section 2.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Type {
    /// An integer that must be present (a count, a degree).
    Integer,
    /// An integer whose default is 0 (a flag, a form, an enumeration).
    Flag,
    /// A real; the default is 0.0.
    Real,
    /// A point: three reals X, Y, Z.
    Point,
    /// A DE pointer to an entity of one of these types (any type when empty); the default
    /// is 0, no entity.
    Pointer(&'static [i64]),
    /// A value when zero or positive, a negated DE pointer to an entity of one of these
    /// types when negative: the line font and color fields (IGES 5.3 sections 2.2.4.4.4 and
    /// 2.2.4.4.13, and the parameters that repeat them); the default is 0.
    ValueOrPointer(&'static [i64]),
    /// A Hollerith string.
    String,
    /// An integer the form fixes to this value (the `NP` of a 406 form whose table gives
    /// one value count): no default, and another value is an [`ErrorKind::Arity`] error.
    Fixed(i64),
}

impl Type {
    /// Parameters one value of this type takes.
    pub fn width(self) -> usize {
        match self {
            Type::Point => 3,
            _ => 1,
        }
    }
}

/// How many times a field occurs.
#[derive(Debug, Clone, Copy)]
pub enum Repeat {
    /// Exactly once.
    One,
    /// Once, or absent when the record ends before it; a default is absent too. A point is
    /// present only when all three of its parameters are.
    Optional,
    /// As many times as the count says.
    Times(Count),
    /// As many times as the count says, or absent when the record ends before it (the
    /// arbitrary values some tables end with).
    OptionalTimes(Count),
    /// The fields of a group, repeated as many times as the count says.
    Group(Count, &'static [Field]),
}

/// A count computed from the integers read before it (the standard's formula, e.g.
/// `K + M + 2` knots), with checked arithmetic: a hostile count is an error, not an
/// allocation.
#[derive(Debug, Clone, Copy)]
pub enum Count {
    /// The value of an `Integer` field read before (e.g. `N`).
    Field(&'static str),
    /// A formula over the integers read before.
    Formula {
        /// The formula as the standard writes it.
        formula: &'static str,
        /// Evaluates it.
        of: fn(&Head) -> Result<usize, String>,
    },
}

impl Count {
    /// The count, given the integers read so far.
    pub fn of(&self, head: &Head) -> Result<usize, String> {
        match self {
            Count::Field(name) => head.count(name),
            Count::Formula { of, .. } => of(head),
        }
    }
}

/// One parameter (or repeated parameters) of an entity.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// The name in the standard's table.
    pub name: &'static str,
    /// Its type.
    pub ty: Type,
    /// How often it occurs.
    pub repeat: Repeat,
}

impl Field {
    /// A field that occurs once.
    pub const fn one(name: &'static str, ty: Type) -> Field {
        Field {
            name,
            ty,
            repeat: Repeat::One,
        }
    }

    /// A field that may be absent at the record's end.
    pub const fn optional(name: &'static str, ty: Type) -> Field {
        Field {
            name,
            ty,
            repeat: Repeat::Optional,
        }
    }

    /// A field repeated `count` times, or absent at the record's end.
    pub const fn optional_times(name: &'static str, ty: Type, count: Count) -> Field {
        Field {
            name,
            ty,
            repeat: Repeat::OptionalTimes(count),
        }
    }

    /// A field repeated `count` times.
    pub const fn times(name: &'static str, ty: Type, count: Count) -> Field {
        Field {
            name,
            ty,
            repeat: Repeat::Times(count),
        }
    }

    /// A group of fields repeated `count` times.
    pub const fn group(name: &'static str, count: Count, fields: &'static [Field]) -> Field {
        Field {
            name,
            ty: Type::Integer,
            repeat: Repeat::Group(count, fields),
        }
    }
}

/// An entity's declaration.
#[derive(Debug, Clone, Copy)]
pub struct Schema {
    /// The entity type number.
    pub entity: i64,
    /// The standard's name for it.
    pub name: &'static str,
    /// The parameters after the entity type, in order.
    pub fields: &'static [Field],
}

/// A typed record of one declared entity.
pub trait Entity: Sized {
    /// Its declaration.
    const SCHEMA: Schema;
    /// The record from the values [`read`] decoded by [`Entity::SCHEMA`] (and the
    /// entry, for the fields a record keeps from its Directory Entry).
    fn from_values(values: Values<'_>, entry: &DirectoryEntry) -> Self;
}

/// The integers read so far (the `Integer` fields), for the counts that follow.
#[derive(Debug, Clone, Default)]
pub struct Head {
    ints: Vec<(&'static str, i64)>,
}

impl Head {
    /// The integer named `name` (the innermost when groups repeat a name).
    #[inline]
    pub fn get(&self, name: &str) -> Result<i64, String> {
        // Names are a byte or two: compared inline rather than through `memcmp`.
        let same =
            |n: &str| n.len() == name.len() && n.bytes().zip(name.bytes()).all(|(a, b)| a == b);
        self.ints
            .iter()
            .rev()
            .find(|(n, _)| same(n))
            .map(|&(_, v)| v)
            .ok_or_else(|| format!("{name} is not read yet"))
    }

    /// The integer named `name` as a count: an error when negative.
    #[inline]
    pub fn count(&self, name: &str) -> Result<usize, String> {
        let v = self.get(name)?;
        usize::try_from(v).map_err(|_| format!("{name} = {v} is negative"))
    }
}

/// A decoded value, by field.
#[derive(Debug, Clone)]
pub enum Value<'a> {
    /// An integer, flag or pointer.
    Int(i64),
    /// A real.
    Real(f64),
    /// A point.
    Point([f64; 3]),
    /// A string (`None`: a default).
    String(Option<&'a str>),
    /// An optional field that is absent.
    Absent,
    /// Repeated integers, flags or pointers.
    Ints(Vec<i64>),
    /// Repeated reals.
    Reals(Vec<f64>),
    /// Repeated points.
    Points(Vec<[f64; 3]>),
    /// Repeated strings.
    Strings(Vec<Option<&'a str>>),
    /// Repeated groups.
    Groups(Vec<Values<'a>>),
}

/// The values of an entity's (or a group's) fields, in declaration order.
#[derive(Debug, Clone)]
pub struct Values<'a> {
    fields: &'static [Field],
    values: Vec<Value<'a>>,
    /// Parameters after the declared ones (the associativity and property pointer groups
    /// with their counts); 0 for a group.
    pub extra: usize,
    /// The associativity and property pointers (IGES 5.3 section 2.2.4.5.2), in that
    /// order.
    pub additional: Vec<i64>,
    /// How many of [`Values::additional`] are associativity pointers (the first group).
    pub associativities: usize,
}

impl<'a> Values<'a> {
    fn slot(&mut self, name: &str) -> Option<&mut Value<'a>> {
        let i = self.fields.iter().position(|f| f.name == name)?;
        self.values.get_mut(i)
    }

    /// Takes field `name`'s value out (a missing field reads as [`Value::Absent`]).
    pub fn take(&mut self, name: &str) -> Value<'a> {
        self.slot(name)
            .map_or(Value::Absent, |v| std::mem::replace(v, Value::Absent))
    }

    /// An integer, flag or pointer field (0 when absent).
    pub fn int(&mut self, name: &str) -> i64 {
        match self.take(name) {
            Value::Int(v) => v,
            _ => 0,
        }
    }

    /// A real field (`None` when absent).
    pub fn real(&mut self, name: &str) -> Option<f64> {
        match self.take(name) {
            Value::Real(v) => Some(v),
            _ => None,
        }
    }

    /// A point field (`None` when absent).
    pub fn point(&mut self, name: &str) -> Option<[f64; 3]> {
        match self.take(name) {
            Value::Point(v) => Some(v),
            _ => None,
        }
    }

    /// A repeated integer or pointer field.
    pub fn ints(&mut self, name: &str) -> Vec<i64> {
        match self.take(name) {
            Value::Ints(v) => v,
            _ => Vec::new(),
        }
    }

    /// A repeated real field.
    pub fn reals(&mut self, name: &str) -> Vec<f64> {
        match self.take(name) {
            Value::Reals(v) => v,
            _ => Vec::new(),
        }
    }

    /// A repeated point field.
    pub fn points(&mut self, name: &str) -> Vec<[f64; 3]> {
        match self.take(name) {
            Value::Points(v) => v,
            _ => Vec::new(),
        }
    }

    /// A repeated group.
    pub fn groups(&mut self, name: &str) -> Vec<Values<'a>> {
        match self.take(name) {
            Value::Groups(v) => v,
            _ => Vec::new(),
        }
    }

    /// Every DE pointer among the values, with its field name and the entity types the
    /// declaration allows it to name (zero pointers, "no entity", left out; a negated
    /// pointer of a [`Type::ValueOrPointer`] field as it is written, negative). The
    /// associativity pointers of section 2.2.4.5.2 are named [`ASSOCIATIVITY_POINTER`]: they
    /// are back pointers to the 402 instances that list the entity (or the 212 General Note
    /// or 312 Text Display Template that section allows in their place); the property
    /// pointers name 406 properties (or the same two text entities).
    pub fn pointers(&self) -> Vec<(&'static str, i64, &'static [i64])> {
        let mut out = Vec::new();
        // The declaration, not the input, bounds the depth: groups nest as the standard's
        // tables do (at most two levels here).
        self.pointers_into(&mut out);
        for (k, &p) in self.additional.iter().enumerate() {
            if p != 0 {
                out.push(if k < self.associativities {
                    (ASSOCIATIVITY_POINTER, p, &[402, 212, 312][..])
                } else {
                    ("property pointer", p, &[406, 212, 312][..])
                });
            }
        }
        out
    }

    fn pointers_into(&self, out: &mut Vec<(&'static str, i64, &'static [i64])>) {
        for (f, v) in self.fields.iter().zip(&self.values) {
            match (f.ty, v) {
                (Type::Pointer(to), Value::Int(p)) if *p != 0 => out.push((f.name, *p, to)),
                (Type::Pointer(to), Value::Ints(ps)) => {
                    out.extend(ps.iter().filter(|&&p| p != 0).map(|&p| (f.name, p, to)));
                }
                (Type::ValueOrPointer(to), Value::Int(p)) if *p < 0 => out.push((f.name, *p, to)),
                (Type::ValueOrPointer(to), Value::Ints(ps)) => {
                    out.extend(ps.iter().filter(|&&p| p < 0).map(|&p| (f.name, p, to)));
                }
                (_, Value::Groups(gs)) => {
                    for g in gs {
                        g.pointers_into(out);
                    }
                }
                _ => {}
            }
        }
    }
}

/// Parameters the declared fields need, given the integers read so far; `None` when a
/// count depends on integers not read yet.
pub fn required(fields: &[Field], head: &Head) -> Option<usize> {
    let mut n = 0usize;
    for f in fields {
        let k = match f.repeat {
            Repeat::One => f.ty.width(),
            Repeat::Optional | Repeat::OptionalTimes(_) => 0,
            Repeat::Times(c) => c.of(head).ok()?.checked_mul(f.ty.width())?,
            Repeat::Group(c, inner) => {
                let count = c.of(head).ok()?;
                if count == 0 {
                    0
                } else {
                    count.checked_mul(required(inner, head)?)?
                }
            }
        };
        n = n.checked_add(k)?;
    }
    Some(n)
}

/// Reads the parameters after the entity type by `schema`, then counts what follows.
///
/// The arity check: once the counts are known, the parameters they need are declared to
/// the reader, so a record that ends early is a [`ErrorKind::Truncated`] error naming the
/// counts; a count that is out of range is an [`ErrorKind::OutOfRange`] error at the first
/// parameter. Nothing is allocated beyond what the remaining data can hold.
pub fn read<'a>(schema: &Schema, r: &mut ParameterReader<'a>) -> Result<Values<'a>, Error<'a>> {
    let first = r.rest();
    let mut head = Head::default();
    if let Some(n) = required(schema.fields, &head) {
        r.expect(n, schema.entity, Vec::new());
    }
    let mut values = read_fields(schema, schema.fields, r, &mut head, first, true)?;
    let start = r.index();
    values.associativities = additional_pointers(r, &mut values.additional)?;
    values.extra = r.index() - start;
    Ok(values)
}

/// The two optional groups after an entity's own parameters (IGES 5.3 section 2.2.4.5.2):
/// `NA` and `NA` associativity pointers, then `NP` and `NP` property pointers. Anything
/// else there (a real, a string, parameters after the last group) means the entity's
/// counts do not match its data: an [`ErrorKind::Arity`] error, never a shifted reading.
///
/// Returns how many of the pointers are associativity pointers (the first group's).
fn additional_pointers<'a>(
    r: &mut ParameterReader<'a>,
    out: &mut Vec<i64>,
) -> Result<usize, Error<'a>> {
    let mut associativities = 0;
    for (group, (count, pointer)) in [
        ("NA (associativity count)", "associativity pointer"),
        ("NP (property count)", "property pointer"),
    ]
    .into_iter()
    .enumerate()
    {
        if r.done() {
            return Ok(associativities);
        }
        let (at, index) = (r.rest(), r.index());
        let n = r.integer(count, Some(0)).map_err(|_| {
            Error::format(
                at,
                ErrorKind::Arity(format!(
                    "parameter {index} is not an integer {count} after the entity's own \
                     parameters: the counts in the record do not match its data"
                )),
            )
        })?;
        let n = usize::try_from(n).map_err(|_| {
            Error::format(
                at,
                ErrorKind::OutOfRange(format!("{count} = {n} is negative")),
            )
        })?;
        for _ in 0..n {
            // One pointer per parameter read: a hostile count allocates nothing ahead.
            out.push(r.integer(pointer, None)?);
        }
        if group == 0 {
            associativities = out.len();
        }
    }
    if r.done() {
        return Ok(associativities);
    }
    let at = r.rest();
    let left = r.skip_rest()?;
    Err(Error::format(
        at,
        ErrorKind::Arity(format!(
            "{left} parameters after the entity's parameters and its associativity and \
             property pointer groups: the counts in the record do not match its data"
        )),
    ))
}

fn read_fields<'a>(
    schema: &Schema,
    fields: &'static [Field],
    r: &mut ParameterReader<'a>,
    head: &mut Head,
    first: &'a [u8],
    top: bool,
) -> Result<Values<'a>, Error<'a>> {
    let mut values = Vec::with_capacity(fields.len());
    let mut expecting = false;
    // An optional parameter was present: the record may not end before the next optional
    // real (the 126's V(0), V(1); the 128's U(0)..V(1) go together).
    let mut tail_started = false;
    for f in fields {
        let count = |c: &Count, head: &Head| {
            c.of(head)
                .map_err(|m| Error::format(first, ErrorKind::OutOfRange(m)))
        };
        if top && !expecting && !matches!(f.repeat, Repeat::One | Repeat::Optional) {
            // The counts are read: declare what the record must hold.
            expecting = true;
            if let Some(n) = required(schema.fields, head) {
                r.expect(n, schema.entity, head.ints.clone());
            }
        }
        let v = match (f.repeat, f.ty) {
            (Repeat::One, ty) => one(r, f.name, ty, head)?,
            (Repeat::Optional, Type::Point) => {
                let (start, at) = (r.index(), r.rest());
                let xyz = [r.parameter()?, r.parameter()?, r.parameter()?];
                match xyz {
                    [Some(x), Some(y), Some(z)] => {
                        let x = r.as_optional_real(x, start, f.name)?;
                        let y = r.as_optional_real(y, start + 1, f.name)?;
                        let z = r.as_optional_real(z, start + 2, f.name)?;
                        match (x, y, z) {
                            (None, None, None) => Value::Absent,
                            (x, y, z) => {
                                Value::Point([x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0)])
                            }
                        }
                    }
                    // The record ended before the point: absent.
                    [None, ..] => Value::Absent,
                    // The record ends inside the point.
                    _ => return Err(tail_cut(at, f.name)),
                }
            }
            (Repeat::Optional, Type::Real) => {
                if r.done() && tail_started {
                    // V(0) without V(1), U(0) without the rest: the record ends inside
                    // a group of parameters that go together.
                    return Err(tail_cut(r.rest(), f.name));
                }
                match r.optional_real(f.name)? {
                    Some(x) => Value::Real(x),
                    None => Value::Absent,
                }
            }
            (Repeat::Optional, ty) => {
                if r.done() {
                    Value::Absent
                } else {
                    one(r, f.name, ty, head)?
                }
            }
            (Repeat::OptionalTimes(_), _) if r.done() => Value::Absent,
            (Repeat::Times(c) | Repeat::OptionalTimes(c), ty) => {
                let n = count(&c, head)?;
                match ty {
                    Type::Real => Value::Reals(r.reals(n, f.name)?),
                    Type::Point => Value::Points(r.points(n, [f.name; 3])?),
                    Type::String => {
                        let mut v = Vec::with_capacity(r.capacity(n, 1));
                        for _ in 0..n {
                            v.push(r.string(f.name)?);
                        }
                        Value::Strings(v)
                    }
                    Type::Integer
                    | Type::Flag
                    | Type::Pointer(_)
                    | Type::ValueOrPointer(_)
                    | Type::Fixed(_) => {
                        let default = (!matches!(ty, Type::Integer | Type::Fixed(_))).then_some(0);
                        let mut v = Vec::with_capacity(r.capacity(n, 1));
                        for _ in 0..n {
                            v.push(r.integer(f.name, default)?);
                        }
                        Value::Ints(v)
                    }
                }
            }
            (Repeat::Group(c, inner), _) => {
                let n = count(&c, head)?;
                let width = required(inner, &Head::default()).unwrap_or(1);
                let mut groups = Vec::with_capacity(r.capacity(n, width));
                for _ in 0..n {
                    let mark = head.ints.len();
                    let at = r.rest();
                    groups.push(read_fields(schema, inner, r, head, at, false)?);
                    head.ints.truncate(mark);
                }
                Value::Groups(groups)
            }
        };
        if matches!(f.repeat, Repeat::Optional | Repeat::OptionalTimes(_)) && !r.done() {
            tail_started = true;
        }
        values.push(v);
    }
    Ok(Values {
        fields,
        values,
        extra: 0,
        additional: Vec::new(),
        associativities: 0,
    })
}

/// The record ends in the middle of its optional parameters (in or before `name`, which
/// starts at `at`).
#[cold]
fn tail_cut<'a>(at: &'a [u8], name: &'static str) -> Error<'a> {
    Error::format(
        trim(at),
        ErrorKind::Arity(format!(
            "the record ends inside its optional parameters, before {name}: the counts in \
             the record do not match its data"
        )),
    )
}

/// One value of a field that occurs once.
fn one<'a>(
    r: &mut ParameterReader<'a>,
    name: &'static str,
    ty: Type,
    head: &mut Head,
) -> Result<Value<'a>, Error<'a>> {
    Ok(match ty {
        Type::Integer => {
            let v = r.integer(name, None)?;
            head.ints.push((name, v));
            Value::Int(v)
        }
        Type::Flag => Value::Int(r.required_flag(name)?),
        Type::Pointer(_) | Type::ValueOrPointer(_) => Value::Int(r.integer(name, Some(0))?),
        Type::Real => Value::Real(r.required_real(name)?),
        Type::Point => Value::Point([
            r.required_real(name)?,
            r.required_real(name)?,
            r.required_real(name)?,
        ]),
        Type::String => Value::String(r.string(name)?),
        Type::Fixed(n) => {
            let at = r.rest();
            let v = r.integer(name, None)?;
            if v != n {
                return Err(Error::format(
                    trim(at),
                    ErrorKind::Arity(format!(
                        "{name} = {v}, but this form has {name} = {n}: the count in the \
                         record does not match its form"
                    )),
                ));
            }
            head.ints.push((name, v));
            Value::Int(v)
        }
    })
}

/// A count as an IGES integer (counts of in-memory data are far below `i64::MAX`).
fn count(n: usize) -> i64 {
    i64::try_from(n).unwrap_or(i64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(ints: &[(&'static str, i64)]) -> Head {
        Head {
            ints: ints.to_vec(),
        }
    }

    /// The declarations against the parameter counts of the standard's tables: a full 126
    /// has `17 + 5K + M` parameters, of which the last five (range, normal) are optional; a
    /// full 128 has `21 + 5 K1 + 5 K2 + 4 K1 K2 + M1 + M2`, the last four optional.
    #[test]
    fn declared_counts_match_the_standard() {
        for (k, m) in [(1i64, 1i64), (3, 3), (6, 2), (10, 5)] {
            let h = head(&[("K", k), ("M", m)]);
            let n = required(curve126::SCHEMA.fields, &h).unwrap();
            assert_eq!(n + 5, usize::try_from(17 + 5 * k + m).unwrap());
        }
        for (k1, k2, m1, m2) in [(3i64, 2i64, 2i64, 1i64), (1, 1, 1, 1), (5, 7, 3, 2)] {
            let h = head(&[("K1", k1), ("K2", k2), ("M1", m1), ("M2", m2)]);
            let n = required(surface128::SCHEMA.fields, &h).unwrap();
            let full = 21 + 5 * k1 + 5 * k2 + 4 * k1 * k2 + m1 + m2;
            assert_eq!(n + 4, usize::try_from(full).unwrap());
        }
        assert_eq!(
            required(transform124::SCHEMA.fields, &Head::default()),
            Some(12)
        );
        // 504: N edges of five parameters.
        let h = head(&[("N", 3)]);
        assert_eq!(required(edge_list504::SCHEMA.fields, &h), Some(1 + 15));
    }

    #[test]
    fn hostile_counts_are_errors() {
        let count = |fields: &[Field], ints: &[(&'static str, i64)]| {
            fields
                .iter()
                .find_map(|f| match f.repeat {
                    Repeat::Times(c) => Some(c.of(&head(ints))),
                    _ => None,
                })
                .unwrap()
        };
        let curve = curve126::SCHEMA.fields;
        assert!(count(curve, &[("K", i64::MAX), ("M", 3)]).is_err());
        assert!(count(curve, &[("K", -1), ("M", 1)]).is_err());
        assert!(count(curve, &[("K", 2), ("M", 3)]).is_err());
        assert!(count(curve, &[("K", 2), ("M", 0)]).is_err());
        let surface = surface128::SCHEMA.fields;
        let big = [("K1", i64::MAX), ("K2", i64::MAX), ("M1", 1), ("M2", 1)];
        assert!(count(surface, &big).is_err());
        // 2^31 - 1 is a count: the record check refuses the record, not the count.
        assert!(count(curve, &[("K", (1 << 31) - 1), ("M", 3)]).is_ok());
    }
}
