//! The declarations of IGES 5.3 entities nurbsx checks but does not convert (204, 213,
//! 310, 312, 316, 320, 322, 412-420, 430, the 416 forms and more 406 forms), each
//! against its table in the standard: a well-formed record, built here parameter by
//! parameter from the table, is read with exactly the pointers the table names; a pointer
//! to no entry or to an entity the table does not allow is found by the validator's rule
//! (an existing odd DE line of an allowed type, `src/exchange/iges/read.rs`), located at
//! the entity and field; a record missing a parameter is an error located at the entity.
//! And the form numbers (DE field 15) the standard gives these types: one it does not
//! give is reported. The layouts read from the data (the 322 in its three forms, the 422
//! by the 322 it names, the 406 forms 11 and 27) are checked the same way by their own
//! checkers.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod iges_support;

use iges_support::{Builder, De};
use nurbsx_parsers::iges::{self, ErrorKind, IgesFile, ParseError};

const GLOBAL: &str = ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,2,2HMM,1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;";

/// The entities the records below point at, in this order (DE pointers 1, 3, 5, ...).
const TARGETS: &[(i64, i64, &str)] = &[
    (116, 0, "116,1.,2.,3.;"),                              // D1 point
    (308, 0, "308,0,4HBASE,1,1;"),                          // D3 subfigure definition
    (124, 0, "124,1.,0.,0.,0.,0.,1.,0.,0.,0.,0.,1.,0.;"),   // D5 transformation
    (320, 0, "320,0,3HNET,1,1,0,2HU1,9,1,11;"),             // D7 network subfigure
    (312, 0, "312,1.,2.,1,1.5708,0.,0,0,0.,0.,0.;"),        // D9 text template
    (132, 0, "132,0.,0.,0.;"),                              // D11 connect point
    (310, 0, "310,1,4HSTD1,0,8,1,65,8,0,2,0,0,0,1,4,8;"),   // D13 text font
    (212, 0, "212,1,4,1.,1.,1,0.,0.,0,0,0.,0.,0.,4HTEXT;"), // D15 general note
    (214, 0, "214,1,1.,1.,0.,0.,0.,1.,1.;"),                // D17 leader
    (110, 0, "110,0.,0.,0.,1.,0.,0.;"),                     // D19 line
    (106, 40, "106,1,2,0.,0.,0.,1.,1.;"),                   // D21 witness line
    (186, 0, "186,0,1,0;"),                                 // D23 B-rep solid
    (134, 0, "134,0.,0.,0.,0;"),                            // D25 node
    (406, 11, "406,6,1,3,0,1.,1.,1.;"),                     // D27 tabular data
];

/// A file of the targets, then the `records` (type, form, parameters) from D29 on.
fn file_text(records: &[(i64, i64, &str)]) -> String {
    let mut b = Builder::new(GLOBAL);
    for &(ty, form, params) in TARGETS.iter().chain(records) {
        b.entity(
            De {
                ty,
                form,
                ..De::default()
            },
            params,
        );
    }
    b.build()
}

/// The DE pointer of `records[k]`.
fn de(k: usize) -> i64 {
    i64::try_from(2 * (TARGETS.len() + k) + 1).unwrap()
}

/// The declared pointers of the entity at `pointer`: `(field, value)`.
fn pointers(file: &IgesFile<'_>, pointer: i64) -> Result<Vec<(&'static str, i64)>, ParseError> {
    let entry = file.entry(pointer).unwrap();
    let refs = file.references(entry).unwrap_or_else(|| {
        panic!(
            "{} form {} has no declaration",
            entry.entity_type, entry.form
        )
    })?;
    Ok(refs.iter().map(|&(n, p, _)| (n, p)).collect())
}

/// The validator's pointer rule on the entity at `pointer`: every declared pointer names
/// an existing entry of a type its field allows. The problems, `(entity, field, value,
/// what)`.
fn pointer_problems(file: &IgesFile<'_>, pointer: i64) -> Vec<(i64, &'static str, i64, String)> {
    let entry = file.entry(pointer).unwrap();
    let refs = file.references(entry).unwrap().unwrap();
    refs.into_iter()
        .filter_map(|(name, value, to)| match file.entry(value) {
            None => Some((pointer, name, value, "no entry".to_owned())),
            Some(t) if !to.is_empty() && !to.contains(&t.entity_type) => {
                Some((pointer, name, value, format!("a {}", t.entity_type)))
            }
            Some(_) => None,
        })
        .collect()
}

/// The record at `pointer` does not hold its declared parameters: an error located at it.
fn arity_error(file: &IgesFile<'_>, pointer: i64) -> ErrorKind {
    let e = pointers(file, pointer).expect_err("a record missing a parameter is an error");
    assert_eq!(
        (e.section, e.de),
        ('P', usize::try_from(pointer).ok()),
        "{e}"
    );
    assert!(
        matches!(
            &e.kind,
            ErrorKind::Truncated { .. } | ErrorKind::Arity(_) | ErrorKind::OutOfRange(_)
        ) || matches!(&e.kind, ErrorKind::BadParameter { found, .. } if found == "<missing>"),
        "{e}"
    );
    e.kind
}

/// A pointer problem the validator's rule finds: field, value, what it names.
type Problem = (&'static str, i64, &'static str);

/// One declared record: well formed, with its pointers changed, and short.
struct Case {
    ty: i64,
    form: i64,
    good: &'static str,
    /// The pointers the table names in `good`, in order.
    expected: &'static [(&'static str, i64)],
    /// `good` with pointers to no entry or to a disallowed type, and the problems.
    bad: Option<(&'static str, &'static [Problem])>,
    /// `good` missing a required parameter.
    short: &'static str,
}

const CASES: &[Case] = &[
    // 412 (section 4.136): DE, S, X, Y, Z, NC, NR, DX, DY, AX, LC, DDF, N(1..LC).
    Case {
        ty: 412,
        form: 0,
        good: "412,3,1.,0.,0.,0.,2,3,10.,20.,0.,1,0,4;",
        expected: &[("DE", 3)],
        bad: Some((
            "412,5,1.,0.,0.,0.,2,3,10.,20.,0.,1,0,4;",
            &[("DE", 5, "a 124")],
        )),
        short: "412,3,1.,0.,0.,0.,2,3,10.,20.,0.,1,0;",
    },
    // 412 on a point, no DO-DON'T list, S defaulted; the base 9999 names no entry.
    Case {
        ty: 412,
        form: 0,
        good: "412,1,,0.,0.,0.,2,2,1.,1.,0.,0,0;",
        expected: &[("DE", 1)],
        bad: Some((
            "412,9999,,0.,0.,0.,2,2,1.,1.,0.,0,0;",
            &[("DE", 9999, "no entry")],
        )),
        short: "412,1,,0.,0.,0.,2,2,1.,1.,0.,0;",
    },
    // 414 (section 4.137): DE, NE, X, Y, Z, R, AS, AD, LC, DDF, N(1..LC).
    Case {
        ty: 414,
        form: 0,
        good: "414,19,6,0.,0.,0.,5.,0.,1.0472,2,1,3,5;",
        expected: &[("DE", 19)],
        bad: Some((
            "414,23,6,0.,0.,0.,5.,0.,1.0472,2,1,3,5;",
            &[("DE", 23, "a 186")],
        )),
        short: "414,19,6,0.,0.,0.,5.,0.,1.0472,2,1,3;",
    },
    // 416 (section 4.138): forms 0 and 2 EXTFID, EXTNAM; 1 EXTFID; 3 EXTNAM; 4 LIBNAM, EXTNAM.
    Case {
        ty: 416,
        form: 0,
        good: "416,9HOTHER.IGS,4HPART;",
        expected: &[],
        bad: None,
        short: "416,9HOTHER.IGS;",
    },
    Case {
        ty: 416,
        form: 1,
        good: "416,9HOTHER.IGS;",
        expected: &[],
        bad: None,
        short: "416;",
    },
    Case {
        ty: 416,
        form: 2,
        good: "416,9HOTHER.IGS,4HPART;",
        expected: &[],
        bad: None,
        short: "416,9HOTHER.IGS;",
    },
    Case {
        ty: 416,
        form: 3,
        good: "416,4HPART;",
        expected: &[],
        bad: None,
        short: "416;",
    },
    Case {
        ty: 416,
        form: 4,
        good: "416,3HLIB,4HPART;",
        expected: &[],
        bad: None,
        short: "416,3HLIB;",
    },
    // 420 (section 4.140): DE, X, Y, Z, XS, YS, ZS, TF, PRD, DPTR, NC, CPTR(1..NC).
    Case {
        ty: 420,
        form: 0,
        good: "420,7,1.,2.,3.,1.,,,2,2HU1,9,1,11;",
        expected: &[("DE", 7), ("DPTR", 9), ("CPTR", 11)],
        bad: Some((
            "420,3,1.,2.,3.,1.,,,2,2HU1,5,1,9999;",
            &[
                ("DE", 3, "a 308"),
                ("DPTR", 5, "a 124"),
                ("CPTR", 9999, "no entry"),
            ],
        )),
        short: "420,7,1.,2.,3.,1.,,,2,2HU1,9,2,11;",
    },
    // 430 (section 4.142): PTR, in both forms.
    Case {
        ty: 430,
        form: 1,
        good: "430,23;",
        expected: &[("PTR", 23)],
        bad: Some(("430,1;", &[("PTR", 1, "a 116")])),
        short: "430;",
    },
    Case {
        ty: 430,
        form: 0,
        good: "430,0;",
        expected: &[],
        bad: Some(("430,9999;", &[("PTR", 9999, "no entry")])),
        short: "430;",
    },
    // 320 (section 4.78): DEPTH, NAME, N, DE(1..N), TF, PRD, PTR, NC, CP(1..NC).
    Case {
        ty: 320,
        form: 0,
        good: "320,1,4HNET2,2,1,19,1,2HU2,9,2,11,11;",
        expected: &[("DE", 1), ("DE", 19), ("PTR", 9), ("CP", 11), ("CP", 11)],
        bad: Some((
            "320,1,4HNET2,2,1,19,1,2HU2,15,2,11,1;",
            &[("PTR", 15, "a 212"), ("CP", 1, "a 116")],
        )),
        short: "320,1,4HNET2,2,1,19,1,2HU2,9,2,11;",
    },
    // 310 (section 4.74): FC, name, superseded font (value or negated 310), scale, NC,
    // NC x (code, NX, NY, NM, NM x (pen flag, X, Y)).
    Case {
        ty: 310,
        form: 0,
        good: "310,2,4HSTD2,-13,8,2,65,8,0,1,0,0,0,66,8,0,2,0,0,0,1,4,8;",
        expected: &[("superseded font", -13)],
        bad: Some((
            "310,2,4HSTD2,-5,8,2,65,8,0,1,0,0,0,66,8,0,2,0,0,0,1,4,8;",
            &[("superseded font", -5, "a 124")],
        )),
        short: "310,2,4HSTD2,-13,8,2,65,8,0,1,0,0,0,66,8,0,2,0,0,0,1,4;",
    },
    // 312 (section 4.75), forms 0 and 1: WT, HT, FC, SL, A, M, VH, X, Y, Z.
    Case {
        ty: 312,
        form: 1,
        good: "312,1.,2.,-13,1.5708,0.,0,1,1.,0.,0.;",
        expected: &[("FC", -13)],
        bad: Some((
            "312,1.,2.,-15,1.5708,0.,0,1,1.,0.,0.;",
            &[("FC", -15, "a 212")],
        )),
        short: "312,1.,2.,-13,1.5708,0.,0,1,1.,0.;",
    },
    // 204 (section 4.56): DENOTE, DECURV1, DECURV2, DEARR1, DEARR2, DEWIT1, DEWIT2.
    Case {
        ty: 204,
        form: 0,
        good: "204,15,19,0,17,17,21,0;",
        expected: &[
            ("DENOTE", 15),
            ("DECURV1", 19),
            ("DEARR1", 17),
            ("DEARR2", 17),
            ("DEWIT1", 21),
        ],
        bad: Some((
            "204,15,19,0,19,17,21,9999;",
            &[("DEARR1", 19, "a 110"), ("DEWIT2", 9999, "no entry")],
        )),
        short: "204,15,19,0,17,17,21;",
    },
    // 213 (section 4.61): the area (12 parameters with NS), then per string 20.
    Case {
        ty: 213,
        form: 0,
        good: "213,10.,5.,1,0.,0.,0.,0.,0.,0.,0.,1.,1,\
               0,1.,1.,0.,0.,1,0.,4HCTRL,4,4.,1.,-13,1.5708,0.,0,0,0.,0.,0.,4HTEXT;",
        expected: &[("character set", -13)],
        bad: Some((
            "213,10.,5.,1,0.,0.,0.,0.,0.,0.,0.,1.,1,\
             0,1.,1.,0.,0.,1,0.,4HCTRL,4,4.,1.,-5,1.5708,0.,0,0,0.,0.,0.,4HTEXT;",
            &[("character set", -5, "a 124")],
        )),
        short: "213,10.,5.,1,0.,0.,0.,0.,0.,0.,0.,1.,1,\
                0,1.,1.,0.,0.,1,0.,4HCTRL,4,4.,1.,-13,1.5708,0.,0,0,0.,0.,0.;",
    },
    // 418 (section 4.139): NC, TYPE, NODE, TABDATA(1..NC).
    Case {
        ty: 418,
        form: 0,
        good: "418,1,2,25,27;",
        expected: &[("NODE", 25), ("TABDATA", 27)],
        bad: Some((
            "418,1,2,1,5;",
            &[("NODE", 1, "a 116"), ("TABDATA", 5, "a 124")],
        )),
        short: "418,2,2,25,27;",
    },
    // 316 (section 4.77): NP, NP x (TYP, VAL, SF).
    Case {
        ty: 316,
        form: 0,
        good: "316,2,6HLENGTH,2HMM,1.,4HMASS,2HKG,1.;",
        expected: &[],
        bad: None,
        short: "316,2,6HLENGTH,2HMM,1.,4HMASS,2HKG;",
    },
    // 322 form 0 (section 4.79): NAME, ATYP, NA, NA x (AT, AVT, AVC), integers.
    Case {
        ty: 322,
        form: 0,
        good: "322,5HTABLE,1,2,10,1,1,11,2,3;",
        expected: &[],
        bad: None,
        short: "322,5HTABLE,1,2,10,1,1,11,2;",
    },
];

/// The 406 forms declared here (sections 4.99-4.132): a well-formed record and one
/// missing a value; none holds a pointer.
const PROPERTIES: &[(i64, &str, &str)] = &[
    (2, "406,3,0,1,2;", "406,3,0,1;"),
    (3, "406,2,3,5HFLOOR;", "406,2;"),
    (5, "406,5,0.5,0,2,1,0.1;", "406,5,0.5,0,2;"),
    (15, "406,1,4HPART;", "406,1;"),
    (16, "406,2,10.,8.;", "406,2,10.;"),
    (17, "406,2,2,2HMM;", "406,2,2;"),
    (18, "406,1,10.;", "406,1;"),
    (19, "406,1,3;", "406,1;"),
    (20, "406,1,1;", "406;"),
    (21, "406,1,0;", "406;"),
    (23, "406,2,2,5HGROUP;", "406,2,2;"),
    (28, "406,6,0,2,1,2HMM,0,3;", "406,6,0,2,1,2HMM,0;"),
    (29, "406,8,0,1,2,0.1,0.1,0,0,2;", "406,8,0,1,2,0.1,0.1,0,0;"),
    (6, "406,5,1.,0.9,1,1,4;", "406,5,1.,0.9,1,1;"),
    (7, "406,1,2HU1;", "406,1;"),
    (8, "406,1,1H3;", "406,1;"),
    (9, "406,4,1HG,1HM,1HV,1HI;", "406,4,1HG,1HM,1HV;"),
    (10, "406,6,0,1,0,1,0,1;", "406,6,0,1,0,1,0;"),
    (12, "406,2,5HA.IGS,5HB.IGS;", "406,2,5HA.IGS;"),
    (13, "406,3,2.5,3HAWG,4HNEMA;", "406,3,2.5,3HAWG;"),
    (13, "406,2,2.5,3HAWG;", "406,2,2.5;"),
    (14, "406,2,4HMAIN,3HHOT;", "406,2,4HMAIN;"),
    (
        22,
        "406,9,1,1,0,0.,0.,1.,1.,10,10;",
        "406,9,1,1,0,0.,0.,1.,1.,10;",
    ),
    (
        24,
        "406,9,2,1,3HTOP,1,5HPad_T,2,3HBOT,4,5HPad_B;",
        "406,9,2,1,3HTOP,1,5HPad_T,2,3HBOT,4;",
    ),
    (25, "406,4,3HART,2,1,2;", "406,4,3HART,2,1;"),
    (26, "406,3,1.,0.9,5;", "406,3,1.,0.9;"),
    (
        31,
        "406,8,0.,0.,2.,0.,2.,1.,0.,1.;",
        "406,8,0.,0.,2.,0.,2.,1.,0.;",
    ),
    (
        32,
        "406,3,3HDOE,3HENG,15H20260101.120000;",
        "406,3,3HDOE,3HENG;",
    ),
    (33, "406,2,1,1HA;", "406,2,1;"),
    (34, "406,7,2,1,1,4,2,3,5;", "406,7,2,1,1,4,2,3;"),
    (35, "406,4,1,1,1,4;", "406,4,1,1,1;"),
    (36, "406,2,2,2;", "406,2,2;"),
    (36, "406,1,1;", "406,1;"),
];

#[test]
fn declared_entities_read_their_tables_pointers() {
    let mut records: Vec<(i64, i64, &str)> = Vec::new();
    for c in CASES {
        records.push((c.ty, c.form, c.good));
        records.push((c.ty, c.form, c.bad.map_or(c.good, |(b, _)| b)));
        records.push((c.ty, c.form, c.short));
    }
    let text = file_text(&records);
    let file = iges::parse(&text).unwrap();
    for (k, c) in CASES.iter().enumerate() {
        let (good, bad, short) = (de(3 * k), de(3 * k + 1), de(3 * k + 2));
        let what = format!("{} form {}: {}", c.ty, c.form, c.good);
        assert_eq!(pointers(&file, good).unwrap(), c.expected, "{what}");
        assert!(pointer_problems(&file, good).is_empty(), "{what}");
        if let Some((_, problems)) = c.bad {
            let found = pointer_problems(&file, bad);
            let want: Vec<_> = problems
                .iter()
                .map(|&(f, p, w)| (bad, f, p, w.to_owned()))
                .collect();
            assert_eq!(found, want, "{what}");
        }
        arity_error(&file, short);
    }
}

/// A record of one form read by another form's declaration does not fit: the forms of 416
/// and 430 are told apart by the DE form number.
#[test]
fn forms_are_declared_apart() {
    let text = file_text(&[
        (416, 1, "416,9HOTHER.IGS,4HPART;"), // form 1 holds one string
        (416, 3, "416,3HLIB,4HPART;"),       // form 3 holds one string
        (416, 4, "416,4HPART;"),             // form 4 holds two
    ]);
    let file = iges::parse(&text).unwrap();
    for k in 0..3 {
        arity_error(&file, de(k));
    }
}

#[test]
fn declared_properties_hold_their_values() {
    let mut records: Vec<(i64, i64, &str)> = Vec::new();
    for &(form, good, short) in PROPERTIES {
        records.push((406, form, good));
        records.push((406, form, short));
    }
    let text = file_text(&records);
    let file = iges::parse(&text).unwrap();
    for (k, &(form, good, _)) in PROPERTIES.iter().enumerate() {
        assert_eq!(
            pointers(&file, de(2 * k)).unwrap(),
            [],
            "406 form {form}: {good}"
        );
        arity_error(&file, de(2 * k + 1));
    }
}

/// Where the form's table fixes NP, another NP is an error at the entity, though the
/// values that follow are those of the form.
#[test]
fn a_fixed_np_is_checked() {
    let wrong: &[(i64, &str)] = &[
        // Sections 4.99-4.101, 4.111-4.117, 4.119, 4.124 and 4.125 fix NP too.
        (2, "406,2,0,1,2;"),
        (3, "406,1,3,5HFLOOR;"),
        (5, "406,4,0.5,0,2,1,0.1;"),
        (15, "406,2,4HPART;"),
        (16, "406,3,10.,8.;"),
        (17, "406,1,2,2HMM;"),
        (18, "406,0,10.;"),
        (19, "406,2,3;"),
        (20, "406,2,1;"),
        (21, "406,,0;"),
        (23, "406,3,2,5HGROUP;"),
        (28, "406,5,0,2,1,2HMM,0,3;"),
        (29, "406,9,0,1,2,0.1,0.1,0,0,2;"),
        (6, "406,4,1.,0.9,1,1,4;"),
        (7, "406,2,2HU1;"),
        (9, "406,3,1HG,1HM,1HV,1HI;"),
        (10, "406,7,0,1,0,1,0,1;"),
        (22, "406,10,1,1,0,0.,0.,1.,1.,10,10;"),
        (26, "406,,1.,0.9,5;"),
        (31, "406,9,0.,0.,2.,0.,2.,1.,0.,1.;"),
        (32, "406,1,3HDOE,3HENG,15H20260101.120000;"),
        (33, "406,3,1,1HA;"),
        (13, "406,4,2.5,3HAWG,4HNEMA;"),
        (34, "406,6,2,1,1,4,2,3,5;"),
        (35, "406,1,1,1,1,4;"),
        (36, "406,3,2,2;"),
        (36, "406,0;"),
    ];
    let records: Vec<(i64, i64, &str)> = wrong.iter().map(|&(f, p)| (406, f, p)).collect();
    let text = file_text(&records);
    let file = iges::parse(&text).unwrap();
    for (k, &(form, params)) in wrong.iter().enumerate() {
        let e = pointers(&file, de(k)).expect_err(params);
        assert_eq!((e.section, e.de), ('P', usize::try_from(de(k)).ok()), "{e}");
        let kind = e.kind;
        assert!(
            matches!(&kind, ErrorKind::Arity(m) | ErrorKind::OutOfRange(m) if m.contains("NP"))
                || matches!(&kind, ErrorKind::BadParameter { name: "NP", .. }),
            "406 form {form}: {params}: {kind:?}"
        );
    }
}

/// `text` with DE field 3 (structure) of the entity at `pointer` set to `value`.
fn with_structure(text: &str, pointer: i64, value: i64) -> String {
    let seq = format!("D{pointer:07}");
    text.lines()
        .map(|l| {
            if l.get(72..80) == Some(seq.as_str()) {
                format!("{}{value:>8}{}", &l[..16], &l[24..])
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// The records whose parameters' types come from their data or from another entity, each
/// written by hand from its layout (D29 on, after the targets): the 322 Attribute Table
/// Definition (section 4.79), the 422 Attribute Table Instance (section 4.141) following
/// the 322 its DE structure field names, the 406 forms 27 Generic Data (section 4.123) and
/// 11 Tabular Data (section 4.107).
const DATA_RECORDS: &[(i64, i64, &str)] = &[
    // D29, 322 form 0: NAME "TABLE", ATYP 0, NA = 2; attribute 1: AT 10, AVT 4 (pointer),
    // AVC 1; attribute 2: AT 11, AVT 2 (real), AVC 2. Form 0 holds no values.
    (322, 0, "322,5HTABLE,0,2,10,4,1,11,2,2;"),
    // D31, 422 form 0 following D29: one row, the pointer (D1, a point), then two reals.
    (422, 0, "422,1,1.5,2.5;"),
    // D33, 422 form 1 following D29: NR = 2, row 1 (D3, 1., 2.), row 2 (D19, 3., 4.).
    (422, 1, "422,2,3,1.,2.,19,3.,4.;"),
    // D35, 322 form 1: NAME "ATTS", ATYP 1, NA = 3; AT 1, AVT 1 (integer), AVC 2: 5, 7;
    // AT 2, AVT 3 (string), AVC 2: "NAME", "PART"; AT 3, AVT 6 (logical), AVC 1: 1.
    (
        322,
        1,
        "322,4HATTS,1,3,1,1,2,5,7,2,3,2,4HNAME,4HPART,3,6,1,1;",
    ),
    // D37, 322 form 2: NAME "TXT", ATYP 1, NA = 2; AT 1, AVT 4 (pointer), AVC 1: D1 with
    // its 312 D9; AT 2, AVT 0 (no value), AVC 1: a default with its 312 D9.
    (322, 2, "322,3HTXT,1,2,1,4,1,1,9,2,0,1,,9;"),
    // D39, 406 form 27: NP = 16, NAME "DATA", TNUM = 7; (1 integer, 42), (2 real, 2.5),
    // (3 string, "OK"), (4 pointer, D19), (0 no value, default), (5 not used, default),
    // (6 logical, 1).
    (406, 27, "406,16,4HDATA,7,1,42,2,2.5,3,2HOK,4,19,0,,5,,6,1;"),
    // D41, 406 form 11: NP = 18, PTYPE 1, NDEP = 1, NIND = 2; TYPIND 1, 2; NVALIN 2, 3;
    // the 2 + 3 independent values; the 6 dependent values (one for each pair of them).
    (
        406,
        11,
        "406,18,1,1,2,1,2,2,3,0.,1.,10.,20.,30.,0.,5.,1.,6.,2.,7.;",
    ),
];

/// The 422 records of [`DATA_RECORDS`] name the 322 at D29 (negated, section 4.141).
fn data_file_text(records: &[(i64, i64, &str)]) -> String {
    let mut text = file_text(records);
    for (k, &(ty, ..)) in records.iter().enumerate() {
        if ty == 422 {
            text = with_structure(&text, de(k), -29);
        }
    }
    text
}

/// Well-formed records of each data-driven layout read with exactly their pointers (the
/// pointer values, and the 312 pointers of a 322 form 2), and the validator's pointer rule
/// finds nothing.
#[test]
fn data_driven_records_read_by_their_layout() {
    let text = data_file_text(DATA_RECORDS);
    let file = iges::parse(&text).unwrap();
    let expected: &[&[(&str, i64)]] = &[
        &[],
        &[("value", 1)],
        &[("value", 3), ("value", 19)],
        &[],
        &[
            ("value", 1),
            ("text display template", 9),
            ("text display template", 9),
        ],
        &[("value", 19)],
        &[],
    ];
    for (k, want) in expected.iter().enumerate() {
        let (ty, form, params) = DATA_RECORDS[k];
        let got = pointers(&file, de(k)).unwrap_or_else(|e| panic!("{ty} form {form}: {e}"));
        assert_eq!(got, *want, "{ty} form {form}: {params}");
        assert!(pointer_problems(&file, de(k)).is_empty(), "{params}");
    }
}

/// One damaged data-driven record in place of `DATA_RECORDS[k]`: the error it must give,
/// at its P line and DE.
fn damaged(k: usize, params: &'static str) -> ErrorKind {
    let mut records = DATA_RECORDS.to_vec();
    records[k].2 = params;
    let text = data_file_text(&records);
    let file = iges::parse(&text).unwrap();
    let e = pointers(&file, de(k)).expect_err(params);
    assert_eq!((e.section, e.de), ('P', usize::try_from(de(k)).ok()), "{e}");
    e.kind
}

/// What an error is, for the tables below: a count that does not match the data
/// (`arity`), a record that ends before its counts' values (`truncated`), a parameter
/// missing at the record's end (`missing`), a parameter of another type (`type`), a value
/// out of its range (`range`).
fn kind_name(kind: &ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Arity(_) => "arity",
        ErrorKind::Truncated { .. } => "truncated",
        ErrorKind::BadParameter { found, .. } if found == "<missing>" => "missing",
        ErrorKind::BadParameter { .. } => "type",
        ErrorKind::OutOfRange(_) => "range",
        _ => "other",
    }
}

/// Counts one too high or too low, a wrong type code, a value of another type than its
/// code names: each an error located at the record.
#[test]
fn damaged_data_driven_records_are_errors() {
    #[rustfmt::skip]
    let cases: &[(usize, &str, &str)] = &[
        // 406 form 27: TNUM one too high (NP kept, then NP raised with it), one too low.
        (5, "406,16,4HDATA,8,1,42,2,2.5,3,2HOK,4,19,0,,5,,6,1;", "arity"),
        (5, "406,18,4HDATA,8,1,42,2,2.5,3,2HOK,4,19,0,,5,,6,1;", "truncated"),
        (5, "406,14,4HDATA,6,1,42,2,2.5,3,2HOK,4,19,0,,5,,6,1;", "missing"),
        // A type code outside 0-6; a real after the integer code 1; a logical of 2.
        (5, "406,16,4HDATA,7,9,42,2,2.5,3,2HOK,4,19,0,,5,,6,1;", "range"),
        (5, "406,16,4HDATA,7,1,4.5,2,2.5,3,2HOK,4,19,0,,5,,6,1;", "type"),
        (5, "406,16,4HDATA,7,1,42,2,2.5,3,2HOK,4,19,0,,5,,6,2;", "range"),
        // 406 form 11: NVALIN(2) = 10, more independent values than NP = 18 can hold; NP
        // one too high (a value missing), one too low (a value left over); a string among
        // the values.
        (6, "406,18,1,1,2,1,2,2,10,0.,1.,10.,20.,30.,0.,5.,1.,6.,2.,7.;", "arity"),
        (6, "406,19,1,1,2,1,2,2,3,0.,1.,10.,20.,30.,0.,5.,1.,6.,2.,7.;", "truncated"),
        (6, "406,17,1,1,2,1,2,2,3,0.,1.,10.,20.,30.,0.,5.,1.,6.,2.,7.;", "arity"),
        (6, "406,18,1,1,2,1,2,2,3,0.,1.,10.,20.,30.,0.,5.,1.,6.,2.,2HAB;", "type"),
        // 322 form 1: the last AVC one too high, one too low; an AVT of 7; a real for an
        // integer attribute.
        (3, "322,4HATTS,1,3,1,1,2,5,7,2,3,2,4HNAME,4HPART,3,6,2,1;", "truncated"),
        (3, "322,4HATTS,1,3,1,1,2,5,7,2,3,2,4HNAME,4HPART,3,6,0,1;", "missing"),
        (3, "322,4HATTS,1,3,1,7,2,5,7,2,3,2,4HNAME,4HPART,3,6,1,1;", "range"),
        (3, "322,4HATTS,1,3,1,1,2,5.,7,2,3,2,4HNAME,4HPART,3,6,1,1;", "type"),
        // 322 form 2: a value without its 312 pointer. Form 0: NA one too high.
        (4, "322,3HTXT,1,2,1,4,1,1,9,2,0,1,;", "truncated"),
        (0, "322,5HTABLE,0,3,10,4,1,11,2,2;", "truncated"),
        // 422 form 0: a value short, a value over, a real for the pointer.
        (1, "422,1,1.5;", "truncated"),
        (1, "422,1,1.5,2.5,3.5;", "arity"),
        (1, "422,1.5,1,2.5;", "type"),
        // 422 form 1: NR one too high, one too low (the second row is left over).
        (2, "422,3,3,1.,2.,19,3.,4.;", "truncated"),
        (2, "422,1,3,1.,2.,19,3.,4.;", "type"),
        // Hostile counts: an error, nothing allocated.
        (5, "406,16,4HDATA,2147483647,1,42;", "arity"),
        (6, "406,18,1,1,3,1,2,3,2147483647,2147483647,2147483647,0.;", "arity"),
        (2, "422,2147483647,3,1.,2.;", "truncated"),
    ];
    for &(k, params, want) in cases {
        let kind = damaged(k, params);
        assert_eq!(kind_name(&kind), want, "{params}: {kind}");
    }
}

/// Pointer values and 312 pointers to an even or missing DE line, or a 312 pointer to
/// another type: found by the validator's rule, named by field.
#[test]
fn data_driven_pointers_are_checked() {
    let cases: &[(usize, &str, &[Problem])] = &[
        (1, "422,99,1.5,2.5;", &[("value", 99, "no entry")]),
        (2, "422,2,4,1.,2.,19,3.,4.;", &[("value", 4, "no entry")]),
        (
            5,
            "406,16,4HDATA,7,1,42,2,2.5,3,2HOK,4,20,0,,5,,6,1;",
            &[("value", 20, "no entry")],
        ),
        (
            4,
            "322,3HTXT,1,2,1,4,1,77,3,2,0,1,,19;",
            &[
                ("value", 77, "no entry"),
                ("text display template", 3, "a 308"),
                ("text display template", 19, "a 110"),
            ],
        ),
    ];
    for &(k, params, want) in cases {
        let mut records = DATA_RECORDS.to_vec();
        records[k].2 = params;
        let text = data_file_text(&records);
        let file = iges::parse(&text).unwrap();
        let got: Vec<(&str, i64, String)> = pointer_problems(&file, de(k))
            .into_iter()
            .map(|(_, f, v, what)| (f, v, what))
            .collect();
        let want: Vec<(&str, i64, String)> =
            want.iter().map(|&(f, v, w)| (f, v, w.to_owned())).collect();
        assert_eq!(got, want, "{params}");
    }
}

/// A 422 whose DE structure field names no entity or an entity other than a 322 has no
/// layout: an error at its DE line. One naming a 322 that does not read is checked no
/// further (the 322's error is its own).
#[test]
fn an_attribute_instance_needs_its_definition() {
    for structure in [0, -1] {
        let text = with_structure(&data_file_text(DATA_RECORDS), de(1), structure);
        let file = iges::parse(&text).unwrap();
        let e = pointers(&file, de(1)).expect_err("no 322");
        assert_eq!((e.section, e.sequence, e.de), ('D', 31, Some(31)), "{e}");
    }
    let mut records = DATA_RECORDS.to_vec();
    records[0].2 = "322,5HTABLE,0,2,10,4;";
    let text = data_file_text(&records);
    let file = iges::parse(&text).unwrap();
    assert!(pointers(&file, de(0)).is_err());
    assert_eq!(pointers(&file, de(1)).unwrap(), []);
}

/// The form numbers (DE field 15) of the types whose form lists came with the annotation
/// and definition entities, read from a file: each type in a form its section gives, and
/// in one it does not give, which the directory check reports at field 15 on the second
/// DE line. 104 (section 4.5), 202-230 (4.55-4.68), 310 (4.74), 312 (4.75), 320 (4.78),
/// 322 (4.79), 412 (4.136), 414 (4.137), 418 (4.139), 420 (4.140), 422 (4.141).
#[test]
fn undefined_forms_of_the_standard_are_reported() {
    let forms: &[(i64, i64, i64)] = &[
        (104, 3, 4),
        (202, 0, 1),
        (204, 0, 1),
        (206, 0, 1),
        (208, 0, 1),
        (210, 0, 1),
        (212, 105, 103),
        (213, 0, 2),
        (214, 12, 0),
        (216, 2, 3),
        (218, 1, 2),
        (220, 0, 1),
        (222, 1, 2),
        (228, 5001, 4),
        (230, 1, 2),
        (310, 0, 1),
        (312, 1, 2),
        (320, 0, 1),
        (322, 2, 3),
        (412, 0, 1),
        (414, 0, 1),
        (418, 0, 1),
        (420, 0, 1),
        (422, 1, 2),
    ];
    let params: Vec<String> = forms.iter().map(|&(ty, _, _)| format!("{ty};")).collect();
    let mut records: Vec<(i64, i64, &str)> = Vec::new();
    for (&(ty, good, bad), p) in forms.iter().zip(&params) {
        records.push((ty, good, p));
        records.push((ty, bad, p));
    }
    let text = file_text(&records);
    let file = iges::parse(&text).unwrap();
    for (k, &(ty, good, bad)) in forms.iter().enumerate() {
        let fields = |pointer: i64| {
            let entry = file.entry(pointer).unwrap();
            assert_eq!(entry.entity_type, ty);
            entry
                .field_problems(None)
                .into_iter()
                .map(|p| (p.field, p.sequence))
                .collect::<Vec<_>>()
        };
        assert_eq!(fields(de(2 * k)), [], "{ty} form {good}");
        let second = usize::try_from(de(2 * k + 1) + 1).unwrap();
        assert_eq!(fields(de(2 * k + 1)), [(15, second)], "{ty} form {bad}");
    }
}
