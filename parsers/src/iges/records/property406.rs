//! Entity 406, Property (IGES 5.3 section 4.97; the forms sections 4.98-4.132): `NP`, then
//! `NP` property values whose types the form defines. None holds a DE pointer among its
//! values; their declarations give the count check and the check of the trailing
//! associativity and property pointers (IGES 5.3 section 2.2.4.5.2). Declared here:
//!
//! | form | name | values after `NP` |
//! | --- | --- | --- |
//! | 1 | Definition Levels (section 4.98) | `NP` level numbers |
//! | 2 | Region Restriction (4.99) | `NP` = 3: vias, components and circuitry flags |
//! | 3 | Level Function (4.100) | `NP` = 2: function code, description (optional) |
//! | 5 | Line Widening (4.101) | `NP` = 5: width, cornering, extension flag, justification, extension value (optional) |
//! | 15 | Name (4.111) | `NP` = 1: the name |
//! | 16 | Drawing Size (4.112) | `NP` = 2: width, height |
//! | 17 | Drawing Units (4.113) | `NP` = 2: units flag, units name |
//! | 18 | Intercharacter Spacing (4.114) | `NP` = 1: spacing |
//! | 19 | Line Font Pattern (4.115) | `NP` = 1: pattern code |
//! | 20 | Highlight (4.116) | `NP` = 1: highlight flag (optional) |
//! | 21 | Pick (4.117) | `NP` = 1: pick flag (optional) |
//! | 23 | Associativity Group Type (4.119) | `NP` = 2: type number, name |
//! | 28 | Dimension Units (4.124) | `NP` = 6: secondary position, units indicator, character set, format, fraction flag, precision |
//! | 29 | Dimension Tolerance (4.125) | `NP` = 8: secondary flag, type, placement, upper and lower tolerance, sign suppression, fraction flag, precision |
//! | 30 | Dimension Display Data (4.126) | type, label position, character set, `L` string, decimal symbol, witness angle, alignment, level, placement, arrowhead orientation, initial value, `NS`, `NS` × (note, start and end index) |
//! | 6 | Drilled Hole (section 4.102) | `NP` = 5: drill and finish diameters, plating flag, lower and higher layer |
//! | 7 | Reference Designator (4.103) | `NP` = 1: the designator |
//! | 8 | Pin Number (4.104) | `NP` = 1: the pin number |
//! | 9 | Part Number (4.105) | `NP` = 4: generic, military, vendor and internal part numbers |
//! | 10 | Hierarchy (4.106) | `NP` = 6: line font, view, level, blank status, line weight and color flags |
//! | 12 | External Reference File List (4.108) | `NP` file names |
//! | 13 | Nominal Size (4.109) | `NP` = 2 or 3: size, name, the engineering standard (when `NP` = 3) |
//! | 14 | Flow Line Specification (4.110) | `NP` strings: the specification name, then modifiers |
//! | 22 | Uniform Rectangular Grid (4.118) | `NP` = 9: finite, line and weighted flags, point `PX, PY`, spacing `DX, DY`, counts `NX, NY` |
//! | 24 | Level to LEP Layer Map (4.120) | `NLD`, `NLD` × (level, native level name, physical layer, functional level name) |
//! | 25 | LEP Artwork Stackup (4.121) | stackup name, `NV`, `NV` level numbers |
//! | 26 | LEP Drilled Hole (4.122) | `NP` = 3: drill and finish diameters, function code |
//! | 31 | Basic Dimension (4.127) | `NP` = 8: the box corners `LLX` .. `ULY` |
//! | 32 | Drawing Sheet Approval (4.128) | `NP` = 3: name, organization, date |
//! | 33 | Drawing Sheet ID (4.129) | `NP` = 2: sheet number, revision identifier |
//! | 34 | Underscore (4.130) | `NP` = 1 + 3 `ND`: `ND`, `ND` × (string, first and last character) |
//! | 35 | Overscore (4.131) | as form 34 |
//! | 36 | Closure (4.132) | `NP` = 1 or 2: closure in U, and in V for a surface |
//!
//! Where the form's table fixes `NP` (forms 2, 3, 5-10, 15-23, 26, 28, 29 and 31-33:
//! [`Type::Fixed`]; 13, 34-36 by a formula) another `NP` is an error. Form 1's `NP` is the
//! count of its levels. Form 30's table (section 4.126) gives `NP` = 14 but lists twelve
//! values and three more per supplemental note, so no one value of `NP` matches every
//! record it describes: its `NP` is read without comparing it. Implementor-defined forms
//! are not declared; their parameters are unchecked.
//!
//! Two forms are beyond a declaration and have their own checkers
//! ([`super::Dependent`]):
//!
//! | form | name | values after `NP` |
//! | --- | --- | --- |
//! | 11 | Tabular Data (section 4.107) | `PTYPE`, `NDEP`, `NIND`, `NIND` types of the independent variables, `NIND` value counts `NVALIN(i)`, the `Σ NVALIN(i)` values of the independent variables (reals), then the values of the dependent variables (reals) up to `NP`, which must count at least `3 + 2 NIND + Σ NVALIN(i)`; how many dependent values `NDEP` and the counts make is not checked (see [`tabular_data`]) |
//! | 27 | Generic Data (section 4.123) | the name (string), `TNUM`, then `TNUM` × (`TYPE`, `VALUE`), each value of the type its code names (0 no value, 1 integer, 2 real, 3 string, 4 pointer, 5 not used, 6 logical); `NP` = `2 + 2 TNUM` |

use super::{
    Count, Field, Head, Schema, Type, count, count_parameter, too_big, trim, typed_value,
    value_type,
};
use crate::iges::error::ErrorKind;
use crate::iges::grammar::parameters::{Error, ParameterReader};

/// Form 1, Definition Levels: `NP`, then the `NP` level numbers.
pub(super) const DEFINITION_LEVELS: Schema = Schema {
    entity: 406,
    name: "Definition Levels Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::times("LEVEL", Type::Flag, Count::Field("NP")),
    ],
};

/// Form 15, Name (section 4.111): `NP` = 1, then the name.
pub(super) const NAME: Schema = Schema {
    entity: 406,
    name: "Name Property",
    fields: &[
        Field::one("NP", Type::Fixed(1)),
        Field::one("NAME", Type::String),
    ],
};

/// A property whose values are the listed fields after `NP`, `NP` read without comparing
/// it (form 30: see the module documentation).
macro_rules! fixed {
    ($name:ident, $title:literal, [$($field:expr),* $(,)?]) => {
        pub(super) const $name: Schema = Schema {
            entity: 406,
            name: $title,
            fields: &[Field::one("NP", Type::Flag), $($field),*],
        };
    };
}

/// A property whose table fixes `NP` to `$np`: the listed fields follow it.
macro_rules! fixed_np {
    ($name:ident, $title:literal, $np:literal, [$($field:expr),* $(,)?]) => {
        pub(super) const $name: Schema = Schema {
            entity: 406,
            name: $title,
            fields: &[Field::one("NP", Type::Fixed($np)), $($field),*],
        };
    };
}

fixed_np!(
    REGION_RESTRICTION,
    "Region Restriction Property",
    3,
    [
        Field::one("VIAS", Type::Flag),
        Field::one("COMPONENTS", Type::Flag),
        Field::one("CIRCUITRY", Type::Flag),
    ]
);
fixed_np!(
    LEVEL_FUNCTION,
    "Level Function Property",
    2,
    [
        Field::one("FC", Type::Flag),
        Field::optional("DESCRIPTION", Type::String),
    ]
);
fixed_np!(
    LINE_WIDENING,
    "Line Widening Property",
    5,
    [
        Field::one("WIDTH", Type::Real),
        Field::one("CORNERING", Type::Flag),
        Field::one("EXTENSION FLAG", Type::Flag),
        Field::one("JUSTIFICATION", Type::Flag),
        Field::optional("EXTENSION", Type::Real),
    ]
);
fixed_np!(
    DRAWING_SIZE,
    "Drawing Size Property",
    2,
    [Field::one("X", Type::Real), Field::one("Y", Type::Real),]
);
fixed_np!(
    DRAWING_UNITS,
    "Drawing Units Property",
    2,
    [
        Field::one("FLAG", Type::Flag),
        Field::one("UNITS", Type::String),
    ]
);
fixed_np!(
    INTERCHARACTER_SPACING,
    "Intercharacter Spacing Property",
    1,
    [Field::one("ISCP", Type::Real),]
);
fixed_np!(
    LINE_FONT_PATTERN,
    "Line Font Pattern Property",
    1,
    [Field::one("LFPC", Type::Flag),]
);
fixed_np!(
    HIGHLIGHT,
    "Highlight Property",
    1,
    [Field::optional("HIGHLIGHT", Type::Flag),]
);
fixed_np!(
    PICK,
    "Pick Property",
    1,
    [Field::optional("PICK", Type::Flag)]
);
fixed_np!(
    ASSOCIATIVITY_GROUP_TYPE,
    "Associativity Group Type Property",
    2,
    [
        Field::one("TYPE", Type::Flag),
        Field::one("NAME", Type::String),
    ]
);
fixed_np!(
    DIMENSION_UNITS,
    "Dimension Units Property",
    6,
    [
        Field::one("SDP", Type::Flag),
        Field::one("UI", Type::Flag),
        Field::one("CS", Type::Flag),
        Field::one("FORMAT", Type::String),
        Field::one("FF", Type::Flag),
        Field::one("PRECISION", Type::Flag),
    ]
);
fixed_np!(
    DIMENSION_TOLERANCE,
    "Dimension Tolerance Property",
    8,
    [
        Field::one("STF", Type::Flag),
        Field::one("TT", Type::Flag),
        Field::one("TPF", Type::Flag),
        Field::one("UPPER", Type::Real),
        Field::one("LOWER", Type::Real),
        Field::one("SS", Type::Flag),
        Field::one("FF", Type::Flag),
        Field::one("PRECISION", Type::Flag),
    ]
);
fixed!(
    DIMENSION_DISPLAY_DATA,
    "Dimension Display Data Property",
    [
        Field::one("DT", Type::Flag),
        Field::one("LP", Type::Flag),
        Field::one("CS", Type::Flag),
        Field::one("L", Type::String),
        Field::one("DS", Type::Flag),
        Field::one("WLA", Type::Real),
        Field::one("TA", Type::Flag),
        Field::one("TL", Type::Flag),
        Field::one("TP", Type::Flag),
        Field::one("AHO", Type::Flag),
        Field::one("IV", Type::Real),
        Field::one("NS", Type::Integer),
        Field::group(
            "note",
            Count::Field("NS"),
            &[
                Field::one("NOTE", Type::Flag),
                Field::one("START", Type::Flag),
                Field::one("END", Type::Flag),
            ],
        ),
    ]
);

fixed_np!(
    DRILLED_HOLE,
    "Drilled Hole Property",
    5,
    [
        Field::one("DDS", Type::Real),
        Field::one("FDS", Type::Real),
        Field::one("PF", Type::Flag),
        Field::one("LNL", Type::Flag),
        Field::one("HNL", Type::Flag),
    ]
);
fixed_np!(
    REFERENCE_DESIGNATOR,
    "Reference Designator Property",
    1,
    [Field::one("RD", Type::String)]
);
fixed_np!(
    PIN_NUMBER,
    "Pin Number Property",
    1,
    [Field::one("PN", Type::String)]
);
fixed_np!(
    PART_NUMBER,
    "Part Number Property",
    4,
    [
        Field::one("GPN", Type::String),
        Field::one("MPN", Type::String),
        Field::one("VPN", Type::String),
        Field::one("IPN", Type::String),
    ]
);
fixed_np!(
    HIERARCHY,
    "Hierarchy Property",
    6,
    [
        Field::one("LF", Type::Flag),
        Field::one("VU", Type::Flag),
        Field::one("LAB", Type::Flag),
        Field::one("BL", Type::Flag),
        Field::one("LW", Type::Flag),
        Field::one("CO", Type::Flag),
    ]
);
fixed_np!(
    UNIFORM_RECTANGULAR_GRID,
    "Uniform Rectangular Grid Property",
    9,
    [
        Field::one("FFLAG", Type::Flag),
        Field::one("LFLAG", Type::Flag),
        Field::one("WFLAG", Type::Flag),
        Field::one("PX", Type::Real),
        Field::one("PY", Type::Real),
        Field::one("DX", Type::Real),
        Field::one("DY", Type::Real),
        Field::one("NX", Type::Flag),
        Field::one("NY", Type::Flag),
    ]
);
fixed_np!(
    LEP_DRILLED_HOLE,
    "LEP Drilled Hole Property",
    3,
    [
        Field::one("DDS", Type::Real),
        Field::one("FDS", Type::Real),
        Field::one("FC", Type::Flag),
    ]
);
fixed_np!(
    BASIC_DIMENSION,
    "Basic Dimension Property",
    8,
    [
        Field::one("LLX", Type::Real),
        Field::one("LLY", Type::Real),
        Field::one("LRX", Type::Real),
        Field::one("LRY", Type::Real),
        Field::one("URX", Type::Real),
        Field::one("URY", Type::Real),
        Field::one("ULX", Type::Real),
        Field::one("ULY", Type::Real),
    ]
);
fixed_np!(
    DRAWING_SHEET_APPROVAL,
    "Drawing Sheet Approval Property",
    3,
    [
        Field::one("NAME", Type::String),
        Field::one("ORG", Type::String),
        Field::one("DATE", Type::String),
    ]
);
fixed_np!(
    DRAWING_SHEET_ID,
    "Drawing Sheet ID Property",
    2,
    [
        Field::one("SNUM", Type::Flag),
        Field::one("SID", Type::String),
    ]
);

/// Form 12, External Reference File List: `NP`, then `NP` file names.
pub(super) const EXTERNAL_REFERENCE_FILE_LIST: Schema = Schema {
    entity: 406,
    name: "External Reference File List Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::times("NAME", Type::String, Count::Field("NP")),
    ],
};

/// Form 14, Flow Line Specification: `NP`, then the specification name and its modifiers.
pub(super) const FLOW_LINE_SPECIFICATION: Schema = Schema {
    entity: 406,
    name: "Flow Line Specification Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::times("L", Type::String, Count::Field("NP")),
    ],
};

/// Form 13, Nominal Size: `NP` (2 or 3), the size, its name, and the engineering standard
/// when `NP` = 3.
pub(super) const NOMINAL_SIZE: Schema = Schema {
    entity: 406,
    name: "Nominal Size Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::one("SZ", Type::Real),
        Field::one("NM", Type::String),
        Field::times(
            "SP",
            Type::String,
            Count::Formula {
                formula: "NP - 2, NP = 2 or 3",
                of: |h: &Head| match h.get("NP")? {
                    np @ 2..=3 => Ok(usize::from(np == 3)),
                    np => Err(format!("NP = {np}: the Nominal Size Property has 2 or 3")),
                },
            },
        ),
    ],
};

/// Form 24, Level to LEP Layer Map: `NP`, `NLD`, then per level its number, native name,
/// physical layer and functional name.
pub(super) const LEVEL_TO_LEP_LAYER_MAP: Schema = Schema {
    entity: 406,
    name: "Level to LEP Layer Map Property",
    fields: &[
        Field::one("NP", Type::Flag),
        Field::one("NLD", Type::Integer),
        Field::group(
            "level",
            Count::Field("NLD"),
            &[
                Field::one("EXCHANGE LEVEL", Type::Flag),
                Field::one("NATIVE LEVEL", Type::String),
                Field::one("PHYSICAL LAYER", Type::Flag),
                Field::one("FUNCTIONAL LEVEL", Type::String),
            ],
        ),
    ],
};

/// Form 25, LEP Artwork Stackup: `NP`, the stackup name, `NV`, then `NV` level numbers.
pub(super) const LEP_ARTWORK_STACKUP: Schema = Schema {
    entity: 406,
    name: "LEP Artwork Stackup Property",
    fields: &[
        Field::one("NP", Type::Flag),
        Field::one("ID", Type::String),
        Field::one("NV", Type::Integer),
        Field::times("L", Type::Flag, Count::Field("NV")),
    ],
};

/// `ND` when `NP` = 1 + 3 `ND` (forms 34 and 35), an error otherwise.
fn scores(h: &Head) -> Result<usize, String> {
    let (np, nd) = (h.get("NP")?, h.count("ND")?);
    match u64::try_from(nd)
        .ok()
        .and_then(|nd| nd.checked_mul(3)?.checked_add(1))
    {
        Some(n) if i64::try_from(n) == Ok(np) => Ok(nd),
        _ => Err(format!("NP = {np} is not 1 + 3 ND with ND = {nd}")),
    }
}

/// The specifications of forms 34 and 35: `ND`, then per specification the text string's
/// index and its first and last character.
const SCORES: [Field; 3] = [
    Field::one("NP", Type::Integer),
    Field::one("ND", Type::Integer),
    Field::group(
        "specification",
        Count::Formula {
            formula: "ND, NP = 1 + 3 ND",
            of: scores,
        },
        &[
            Field::one("T", Type::Flag),
            Field::one("F", Type::Flag),
            Field::one("L", Type::Flag),
        ],
    ),
];

/// Form 34, Underscore.
pub(super) const UNDERSCORE: Schema = Schema {
    entity: 406,
    name: "Underscore Property",
    fields: &SCORES,
};

/// Form 35, Overscore.
pub(super) const OVERSCORE: Schema = Schema {
    entity: 406,
    name: "Overscore Property",
    fields: &SCORES,
};

/// Form 36, Closure: `NP` (1 or 2, no default), then the closure flag in U and, for a
/// surface, in V.
pub(super) const CLOSURE: Schema = Schema {
    entity: 406,
    name: "Closure Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::times(
            "CLOSED",
            Type::Flag,
            Count::Formula {
                formula: "NP, 1 or 2",
                of: |h: &Head| match h.get("NP")? {
                    np @ 1..=2 => Ok(usize::from(np == 2) + 1),
                    np => Err(format!("NP = {np}: the Closure Property has 1 or 2")),
                },
            },
        ),
    ],
};

/// `NP` against the values the record's counts declare (`expected`): another value is an
/// [`ErrorKind::Arity`] error at `NP` (at `at`).
fn check_np<'a>(at: &'a [u8], np: i64, expected: usize, counts: &str) -> Result<(), Error<'a>> {
    if usize::try_from(np).ok() == Some(expected) {
        return Ok(());
    }
    Err(Error::format(
        trim(at),
        ErrorKind::Arity(format!(
            "NP = {np}, but {counts} declare {expected} property values: the counts in the \
             record do not match its data"
        )),
    ))
}

/// Form 11, Tabular Data (section 4.107): checks the parameters after the entity type
/// (see the module documentation). Every count is checked and every value read one by
/// one: nothing is allocated. The values after the independent ones, up to `NP`, are the
/// dependent values, each a real; how many `NDEP` and the `NVALIN(i)` make is not checked
/// (nurbsx has no text of section 4.107 that fixes it, and Open CASCADE's reader takes every
/// real that follows), so a valid table is never refused for its layout.
pub(super) fn tabular_data<'a>(r: &mut ParameterReader<'a>) -> Result<(), Error<'a>> {
    let first = r.rest();
    let np = r.integer("NP", None)?;
    r.integer("PTYPE", Some(0))?;
    let ndep = count_parameter(r, "NDEP", None)?;
    let nind = count_parameter(r, "NIND", None)?;
    let head = nind
        .checked_mul(2)
        .and_then(|n| n.checked_add(4))
        .ok_or_else(|| too_big(first, "4 + 2 NIND"))?;
    r.expect(
        head,
        406,
        vec![("NDEP", count(ndep)), ("NIND", count(nind))],
    );
    for _ in 0..nind {
        // One parameter per turn: the data, not the count, bounds the loop.
        r.integer("TYPIND", Some(0))?;
    }
    let mut sum = Some(0usize);
    for _ in 0..nind {
        let n = count_parameter(r, "NVALIN", None)?;
        sum = sum.and_then(|s| s.checked_add(n));
    }
    let independent = sum.ok_or_else(|| too_big(first, "Σ NVALIN"))?;
    // Parameters through the independent values, `NP` included; `NP` counts the rest.
    let through = head
        .checked_add(independent)
        .ok_or_else(|| too_big(first, "the value count"))?;
    let dependent = usize::try_from(np)
        .ok()
        .and_then(|np| np.checked_sub(through - 1))
        .ok_or_else(|| {
            Error::format(
                trim(first),
                ErrorKind::Arity(format!(
                    "NP = {np}, but NIND and NVALIN declare at least {} property values: \
                     the counts in the record do not match its data",
                    through - 1
                )),
            )
        })?;
    r.expect(
        through.saturating_add(dependent),
        406,
        vec![
            ("NP", np),
            ("NIND", count(nind)),
            ("Σ NVALIN", count(independent)),
        ],
    );
    for _ in 0..independent {
        r.real("VALIN")?;
    }
    for _ in 0..dependent {
        r.real("VALDEP")?;
    }
    Ok(())
}

/// Form 27, Generic Data (section 4.123): checks the parameters after the entity type
/// (see the module documentation); the pointer values go to `pointers`.
pub(super) fn generic_data<'a>(
    r: &mut ParameterReader<'a>,
    pointers: &mut Vec<i64>,
) -> Result<(), Error<'a>> {
    let first = r.rest();
    let np = r.integer("NP", None)?;
    r.string("NAME")?;
    let tnum = count_parameter(r, "TNUM", None)?;
    let needed = tnum
        .checked_mul(2)
        .and_then(|n| n.checked_add(3))
        .ok_or_else(|| too_big(first, "3 + 2 TNUM"))?;
    r.expect(needed, 406, vec![("TNUM", count(tnum))]);
    check_np(first, np, needed - 1, "TNUM")?;
    for _ in 0..tnum {
        let code = value_type(r, "TYPE")?;
        typed_value(r, code, "VALUE", pointers)?;
    }
    Ok(())
}
