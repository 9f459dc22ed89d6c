//! Part 21 grammar corners: valid input -> exact syntax tree, invalid input -> exact error
//! kind, line, column and #id (ISO 10303-21:2016 clauses 6-12; pitfalls.md E.23-27).
// Helpers outside #[test] functions may fail loudly too: they only run under tests.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use nurbsx_parsers::Limits;
use nurbsx_parsers::step::{
    Body, Parameter, ParseError, ParseErrorKind, Parsed, Record, StepString, parse, scan,
    write_exchange,
};

const HEAD: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('d'),'2;1');\nFILE_NAME('n','t',('a'),('o'),'p','s','x');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n";
const TAIL: &str = "ENDSEC;\nEND-ISO-10303-21;\n";

/// Wraps data lines into a file: the first data line is line 8.
fn file(data: &str) -> String {
    format!("{HEAD}{data}\n{TAIL}")
}

fn parsed(text: &str) -> Parsed<'_> {
    parse(text, &Limits::default()).expect("structure")
}

fn only_body(text: &str) -> Body<'_> {
    let p = parsed(text);
    assert!(p.errors.is_empty(), "{:?}", p.errors);
    let mut it = p.exchange.instances();
    let inst = it.next().expect("one instance").clone();
    inst.body
}

fn one_error(text: &str) -> ParseError {
    let p = parsed(text);
    assert_eq!(p.errors.len(), 1, "{:?}", p.errors);
    p.errors[0].clone()
}

fn s(raw: &str) -> Parameter<'_> {
    Parameter::String(StepString::new(raw))
}

#[test]
fn simple_instance_with_every_parameter_kind() {
    let t = file(
        "#1=E('a''b',12,-3.5E-2,.T.,#2,$,*,\"0F\",(),((1,2),()),LENGTH_MEASURE(1.E-07));\n#2=F();",
    );
    let body = only_body(&t);
    let want = Body::Simple(Record {
        keyword: "E",
        params: vec![
            s("a''b"),
            Parameter::Integer(12),
            Parameter::Real(-3.5e-2),
            Parameter::Enumeration("T"),
            Parameter::Reference(2),
            Parameter::Null,
            Parameter::Derived,
            Parameter::Binary("0F"),
            Parameter::List(vec![]),
            Parameter::List(vec![
                Parameter::List(vec![Parameter::Integer(1), Parameter::Integer(2)]),
                Parameter::List(vec![]),
            ]),
            Parameter::Typed("LENGTH_MEASURE", Box::new(Parameter::Real(1e-7))),
        ],
    });
    assert_eq!(body, want);
}

#[test]
fn complex_instance_comments_crlf_and_whitespace_anywhere() {
    let data = "#7 /* c1 */ = /* 'not a string; */ (\r\n  BOUNDED_CURVE ( ) B_SPLINE_CURVE(2,(#1,\r\n#2),.UNSPECIFIED.,.F.,.F.)\r\n /* ; */ REPRESENTATION_ITEM('x;y') ) ;\n#1=P();#2=P();";
    let t = file(data);
    let body = only_body(&t);
    let Body::Complex(rs) = body else {
        panic!("complex")
    };
    let names: Vec<_> = rs.iter().map(|r| r.keyword).collect();
    assert_eq!(
        names,
        ["BOUNDED_CURVE", "B_SPLINE_CURVE", "REPRESENTATION_ITEM"]
    );
    assert_eq!(rs[2].params, vec![s("x;y")]);
    assert_eq!(rs[1].params[1], Parameter::refs(&[1, 2]));
}

#[test]
fn user_defined_keyword_and_strings_over_lines() {
    let t = file("#1=!MY_THING('first\nsecond');");
    let body = only_body(&t);
    let Body::Simple(r) = body else { panic!() };
    assert_eq!(r.keyword, "!MY_THING");
    assert_eq!(
        r.params[0].as_string().unwrap().decode().unwrap(),
        "firstsecond"
    );
}

#[test]
fn header_is_decoded_and_multiple_schemas() {
    let t = "ISO-10303-21;HEADER;/* it's a comment */FILE_DESCRIPTION(('a'),'2;1');FILE_NAME('x','y',(''),(''),'','','');FILE_SCHEMA(('A','B { 1 2 }'));ENDSEC;DATA;ENDSEC;END-ISO-10303-21;";
    let p = parsed(t);
    assert!(p.errors.is_empty(), "{:?}", p.errors);
    let names: Vec<_> = p
        .exchange
        .schemas()
        .iter()
        .map(|s| s.decode().unwrap().into_owned())
        .collect();
    assert_eq!(names, ["A", "B { 1 2 }"]);
}

#[test]
fn several_data_sections_and_edition3_sections() {
    let t = format!(
        "{HEAD}#1=A();\nENDSEC;\nANCHOR;\n<x> = #1;\nENDSEC;\nDATA('second',('S'));\n#2=B(#1);\n{TAIL}"
    );
    let p = parsed(&t);
    assert_eq!(p.exchange.data.len(), 2);
    assert_eq!(p.exchange.data[1].params.len(), 2);
    assert_eq!(p.exchange.instances().count(), 2);
    assert_eq!(p.errors.len(), 1);
    assert_eq!(p.errors[0].kind, ParseErrorKind::SkippedSection("ANCHOR"));
    assert_eq!((p.errors[0].line, p.errors[0].column), (10, 1));
}

#[test]
fn string_escape_table() {
    let cases: &[(&str, Result<&str, usize>)] = &[
        ("\\X2\\041F04300440044204350440\\X0\\", Ok("Партер")),
        ("\\X2\\041f0430\\X0\\", Ok("Па")),
        ("\\X\\E9t\\X\\e9", Ok("été")),
        ("O''Brien", Ok("O'Brien")),
        ("\\S\\a", Ok("á")),
        ("\\PA\\\\S\\a", Ok("á")),
        ("a\\\\b", Ok("a\\b")),
        ("\\X4\\0001F600\\X0\\", Ok("😀")),
        ("\\X2\\D83DDE00\\X0\\", Ok("😀")),
        ("x\\N\\y", Ok("x\ny")),
        ("\\X2\\00", Err(0)),
        ("ab\\X2\\0041", Err(2)),
        ("\\X\\G1", Err(0)),
        ("c:\\temp", Err(2)),
        ("\\X2\\D83D\\X0\\", Err(0)),
    ];
    for (raw, want) in cases {
        let ss = StepString::new(raw);
        let got = ss.decode();
        match (got, want) {
            (Ok(g), Ok(w)) => assert_eq!(g, *w, "{raw}"),
            (Err(e), Err(at)) => assert_eq!(e.offset, *at, "{raw}"),
            (g, w) => panic!("{raw}: got {g:?}, want {w:?}"),
        }
    }
}

#[test]
fn located_errors_with_line_column_and_id() {
    // Data starts on line 8.
    let cases: &[(&str, ParseErrorKind, usize, usize, Option<u64>)] = &[
        (
            "#5=A(1.52.3);",
            ParseErrorKind::InvalidReal("1.52.3".into()),
            8,
            6,
            Some(5),
        ),
        (
            "#5=A(1.E400);",
            ParseErrorKind::NonFiniteReal("1.E400".into()),
            8,
            6,
            Some(5),
        ),
        (
            "#5=A(1.e5);",
            ParseErrorKind::InvalidReal("1.e5".into()),
            8,
            6,
            Some(5),
        ),
        (
            "#5=A(.5);",
            ParseErrorKind::Expected {
                expected: "an upper-case enumeration value",
                found: "`5)`".into(),
            },
            8,
            7,
            Some(5),
        ),
        (
            "#6=\n  b_spline(1);",
            ParseErrorKind::LowercaseKeyword("b_spline".into()),
            9,
            3,
            Some(6),
        ),
        (
            "#7=A(1,,2);",
            ParseErrorKind::Expected {
                expected: "a parameter",
                found: "`,2)`".into(),
            },
            8,
            8,
            Some(7),
        ),
        (
            "#7=A(1 2);",
            ParseErrorKind::Expected {
                expected: "`,` or `)`",
                found: "`2)`".into(),
            },
            8,
            8,
            Some(7),
        ),
        (
            "#7=A(1,);",
            ParseErrorKind::Expected {
                expected: "a parameter after `,`",
                found: "`)`".into(),
            },
            8,
            8,
            Some(7),
        ),
        (
            "#7=A(99999999999999999999);",
            ParseErrorKind::IntegerOverflow("99999999999999999999".into()),
            8,
            6,
            Some(7),
        ),
        (
            "#7=A(#99999999999999999999);",
            ParseErrorKind::InvalidId("99999999999999999999".into()),
            8,
            6,
            Some(7),
        ),
        (
            "#99999999999999999999=A();",
            ParseErrorKind::InvalidId("99999999999999999999".into()),
            8,
            1,
            None,
        ),
        (
            "#8=A(X(1,2));",
            ParseErrorKind::TypedArity("X".into()),
            8,
            6,
            Some(8),
        ),
        (
            "#8=A(\"5F\");",
            ParseErrorKind::InvalidBinary,
            8,
            6,
            Some(8),
        ),
        (
            "#8=A() B();",
            ParseErrorKind::Expected {
                expected: "`;`",
                found: "`B()`".into(),
            },
            8,
            8,
            Some(8),
        ),
        (
            "#9 A();",
            ParseErrorKind::Expected {
                expected: "`=` after the instance name",
                found: "`A()`".into(),
            },
            8,
            4,
            Some(9),
        ),
        (
            "X=A();",
            ParseErrorKind::Expected {
                expected: "`#` starting an entity instance, or ENDSEC;",
                found: "`X=A()`".into(),
            },
            8,
            1,
            None,
        ),
    ];
    for (data, kind, line, column, entity) in cases {
        let e = one_error(&file(data));
        assert_eq!(
            (&e.kind, e.line, e.column, e.entity),
            (kind, *line, *column, *entity),
            "input {data}"
        );
    }
}

#[test]
fn one_bad_instance_does_not_lose_the_file() {
    let t = file("#1=A(1);\n#2=B(1.2.3,'it''s;fine');\n#3=C(/* ; */ 3);");
    let p = parsed(&t);
    assert_eq!(p.errors.len(), 1);
    assert_eq!((p.errors[0].line, p.errors[0].entity), (9, Some(2)));
    let ids: Vec<u64> = p.exchange.instances().map(|i| i.id).collect();
    assert_eq!(ids, [1, 3]);
}

#[test]
fn duplicate_and_dangling_ids() {
    let t = file("#1=A(#2);\n#1=B();\n#3=C(#404);");
    let p = parsed(&t);
    let kinds: Vec<_> = p
        .errors
        .iter()
        .map(|e| (e.kind.clone(), e.line, e.entity))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (ParseErrorKind::DanglingReference(2), 8, Some(1)),
            (
                ParseErrorKind::DuplicateId {
                    id: 1,
                    first_line: 8
                },
                9,
                Some(1)
            ),
            (ParseErrorKind::DanglingReference(404), 10, Some(3)),
        ]
    );
}

#[test]
fn self_reference_and_two_cycle_are_found() {
    let t = file("#1=A(#1);\n#2=B((#3));\n#3=C(#2);\n#4=D(#5);\n#5=E();");
    let s = scan(&t, &Limits::default()).unwrap();
    let errs = s.find_cycles([1, 2, 4]);
    let got: Vec<_> = errs
        .iter()
        .map(|e| (e.kind.clone(), e.line, e.entity))
        .collect();
    assert_eq!(
        got,
        vec![
            (ParseErrorKind::ReferenceCycle(vec![1, 1]), 8, Some(1)),
            (ParseErrorKind::ReferenceCycle(vec![2, 3, 2]), 10, Some(3)),
        ]
    );
}

#[test]
fn deep_nesting_is_a_clean_error() {
    let n = 100_000;
    let data = format!("#1=A({}{});", "(".repeat(n), ")".repeat(n));
    let e = one_error(&file(&data));
    assert_eq!(e.kind, ParseErrorKind::NestingTooDeep(64));
    assert_eq!((e.line, e.column, e.entity), (8, 5 + 64, Some(1)));
    // Typed parameters count as nesting too.
    let data = format!("#1=A({}1{});", "X(".repeat(n), ")".repeat(n));
    assert_eq!(
        one_error(&file(&data)).kind,
        ParseErrorKind::NestingTooDeep(64)
    );
}

#[test]
fn broken_structure_is_fatal_and_garbage_is_reported() {
    let e = parse("HEADER;", &Limits::default()).unwrap_err();
    assert_eq!(
        (e.kind, e.line, e.column),
        (ParseErrorKind::Missing("ISO-10303-21;"), 1, 1)
    );
    let e = parse("ISO-10303-21;\nDATA;", &Limits::default()).unwrap_err();
    assert_eq!(
        (e.kind, e.line, e.column),
        (ParseErrorKind::Missing("HEADER;"), 2, 1)
    );
    let t = format!("{}junk", file(""));
    let e = one_error(&t);
    assert_eq!(e.kind, ParseErrorKind::TrailingGarbage);
    assert_eq!((e.line, e.column), (11, 1));
    let t = format!("{HEAD}#1=A();\n");
    let p = parsed(&t);
    let kinds: Vec<_> = p.errors.iter().map(|e| (e.kind.clone(), e.line)).collect();
    assert_eq!(
        kinds,
        vec![
            (ParseErrorKind::Missing("ENDSEC; closing DATA"), 9),
            (ParseErrorKind::Missing("END-ISO-10303-21;"), 9)
        ]
    );
}

#[test]
fn limits_are_enforced() {
    let limits = Limits {
        max_entities: 2,
        ..Limits::default()
    };
    let e = parse(&file("#1=A();#2=A();#3=A();"), &limits).unwrap_err();
    assert_eq!(
        (e.kind, e.entity),
        (ParseErrorKind::TooManyInstances(2), Some(3))
    );
    let limits = Limits {
        max_params_per_entity: 3,
        ..Limits::default()
    };
    let t = file("#1=A((1,2),3);");
    let p = parse(&t, &limits).unwrap();
    assert_eq!(p.errors[0].kind, ParseErrorKind::TooManyParameters(3));
}

/// Real Open CASCADE 7.5 output (spec.md c.2 and c.4).
const OCCT: &str = "ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('Open CASCADE Model'),'2;1');
FILE_NAME('Open CASCADE Shape Model','2021-07-04T17:24:58',('Author'),(
    'Open CASCADE'),'Open CASCADE STEP processor 7.5','Open CASCADE 7.5','Unknown');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));
ENDSEC;
DATA;
#358 = ( BOUNDED_CURVE() B_SPLINE_CURVE(2,(#359,#360,#361,#362,#363,#364
,#365),.UNSPECIFIED.,.T.,.F.) B_SPLINE_CURVE_WITH_KNOTS((1,2,2,2,2,1),(
    -2.094395102393,0.,2.094395102393,4.188790204786,6.28318530718,
8.377580409573),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM()
RATIONAL_B_SPLINE_CURVE((1.,0.5,1.,0.5,1.,0.5,1.)) REPRESENTATION_ITEM(
  '') );
#1885 = B_SPLINE_SURFACE_WITH_KNOTS('',6,1,((#1886,#1887),(#1914,#1915)),
.UNSPECIFIED.,.F.,.F.,.F.,(7,4,4,7),(2,2),(0.,0.5,0.514772540266,1.),(0.,1.),.UNSPECIFIED.);
#23 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#20,
  'distance_accuracy_value','confusion accuracy');
ENDSEC;
END-ISO-10303-21;
";

#[test]
#[allow(clippy::approx_constant)] // 6.28318530718 is OCCT's 12-digit 2*pi, quoted verbatim
fn occt_excerpts_parse_exactly() {
    let p = parsed(OCCT);
    // Only dangling references (the excerpt leaves the points out).
    assert!(
        p.errors
            .iter()
            .all(|e| matches!(e.kind, ParseErrorKind::DanglingReference(_)))
    );
    let insts: Vec<_> = p.exchange.instances().collect();
    assert_eq!(insts.len(), 3);
    let Body::Complex(rs) = &insts[0].body else {
        panic!()
    };
    assert_eq!(rs.len(), 7);
    assert_eq!(
        rs[2].params[1],
        Parameter::reals(&[
            -2.094395102393,
            0.,
            2.094395102393,
            4.188790204786,
            6.28318530718,
            8.377580409573
        ])
    );
    assert_eq!(
        rs[5].params[0],
        Parameter::reals(&[1., 0.5, 1., 0.5, 1., 0.5, 1.])
    );
    let Body::Simple(r) = &insts[1].body else {
        panic!()
    };
    assert_eq!(r.params.len(), 13);
    assert_eq!(r.params[8], Parameter::integers(&[7, 4, 4, 7]));
    let Body::Simple(r) = &insts[2].body else {
        panic!()
    };
    assert_eq!(
        r.params[0],
        Parameter::Typed("LENGTH_MEASURE", Box::new(Parameter::Real(1e-7)))
    );
}

#[test]
fn parse_write_parse_is_identity() {
    let p = parsed(OCCT);
    let text = write_exchange(&p.exchange).unwrap();
    assert!(text.is_ascii());
    let q = parsed(&text);
    assert_eq!(p.exchange, q.exchange);
    // Partials come out sorted byte-wise: BOUNDED_CURVE before B_SPLINE_CURVE.
    let b = text.find("BOUNDED_CURVE").unwrap();
    assert!(b < text.find("B_SPLINE_CURVE(").unwrap());
}

#[test]
fn writer_escapes_strings_to_ascii() {
    use nurbsx_parsers::step::{Builder, DataSection, Exchange};
    let mut b = Builder::new();
    b.simple("N", vec![Parameter::text("Партер O'Brien \\ é 😀")]);
    let ex = Exchange {
        header: vec![],
        data: vec![DataSection {
            params: vec![],
            instances: b.into_instances(),
        }],
    };
    let text = write_exchange(&ex).unwrap();
    assert!(text.contains("'\\X2\\041F04300440044204350440\\X0\\ O''Brien \\\\ \\X2\\00E9\\X0\\ \\X2\\D83DDE00\\X0\\'"), "{text}");
    let p = parsed(&text);
    let inst = p.exchange.instances().next().unwrap();
    let Body::Simple(r) = &inst.body else {
        panic!()
    };
    assert_eq!(
        r.params[0].as_string().unwrap().decode().unwrap(),
        "Партер O'Brien \\ é 😀"
    );
}

mod roundtrip_props {
    use super::*;
    use nurbsx_parsers::step::{Builder, DataSection, Exchange};
    use proptest::prelude::*;

    fn leaf() -> impl Strategy<Value = Parameter<'static>> {
        prop_oneof![
            any::<i64>().prop_map(Parameter::Integer),
            any::<f64>()
                .prop_filter("finite", |x| x.is_finite())
                .prop_map(Parameter::Real),
            "[ -~\\PL]{0,8}".prop_map(|s| Parameter::text(&s)),
            prop_oneof![Just("T"), Just("F"), Just("UNSPECIFIED"), Just("X_1")]
                .prop_map(Parameter::Enumeration),
            (0u64..u64::MAX).prop_map(Parameter::Reference),
            Just(Parameter::Null),
            Just(Parameter::Derived),
            Just(Parameter::Binary("3AF")),
        ]
    }

    fn param() -> impl Strategy<Value = Parameter<'static>> {
        leaf().prop_recursive(4, 32, 5, |inner| {
            prop_oneof![
                prop::collection::vec(inner.clone(), 0..5).prop_map(Parameter::List),
                inner.prop_map(|p| Parameter::Typed("LENGTH_MEASURE", Box::new(p))),
            ]
        })
    }

    proptest! {
        #[test]
        fn arbitrary_ast_roundtrips(params in prop::collection::vec(prop::collection::vec(param(), 0..6), 1..6), complex in any::<bool>()) {
            let mut b = Builder::new();
            let names = ["ALPHA", "BETA", "B_ETA", "GAMMA_2", "ZETA", "DELTA"];
            if complex {
                let recs = params.iter().enumerate().map(|(i, p)| Record { keyword: names[i], params: p.clone() }).collect();
                b.complex(recs);
            } else {
                for p in &params {
                    b.simple("ENTITY", p.clone());
                }
            }
            let ex = Exchange { header: vec![Record { keyword: "FILE_SCHEMA", params: vec![Parameter::List(vec![Parameter::text("S")])] }], data: vec![DataSection { params: vec![], instances: b.into_instances() }] };
            let text = write_exchange(&ex).unwrap();
            let p = parse(&text, &Limits::default()).unwrap();
            let dangling_only = p.errors.iter().all(|e| matches!(e.kind, ParseErrorKind::DanglingReference(_)));
            prop_assert!(dangling_only, "{:?}", p.errors);
            // Strings compare by decoded value (raw text is re-encoded by the builder).
            prop_assert_eq!(format!("{:?}", normalise(&p.exchange)), format!("{:?}", normalise(&ex)));
        }
    }

    fn normalise(ex: &Exchange<'_>) -> Vec<String> {
        ex.instances().map(|i| format!("{:?}", i)).collect()
    }
}

mod hostile {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        /// Any data section text: no panic, and every error is located inside the input.
        #[test]
        fn arbitrary_data_never_panics(data in "[#=(),;'\"./*$A-Z0-9E+\\- \n\\\\!a-z]{0,200}") {
            let t = file(&data);
            if let Ok(p) = parse(&t, &Limits::default()) {
                for e in &p.errors {
                    prop_assert!(e.offset <= t.len() && e.line >= 1 && e.column >= 1);
                }
                let _ = write_exchange(&p.exchange);
            }
            let s = scan(&t, &Limits::default());
            if let Ok(s) = s {
                let ids: Vec<u64> = s.instances.iter().map(|r| r.id).collect();
                let _ = s.find_cycles(ids);
            }
        }
    }
}
