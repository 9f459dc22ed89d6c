//! Column-exact IGES fixtures: slot arithmetic with sentinels, Global section forms,
//! comments, exponents, and located errors. Files are built by `iges_support`, which
//! formats every record by hand (not with the crate's writer).
// Test fixtures cast small literal counts and indexes; the cast lints guard input-derived
// numbers in the library itself.
#![allow(
    clippy::cast_possible_wrap,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod iges_support;

use iges_support::{Builder, De, OCCT_GLOBAL, rec, seq_reals};
use nurbsx_parsers::iges::{
    self, ErrorKind,
    records::{Curve126, Surface128, Transform124},
};

const DEFAULT_GLOBAL: &str = ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,2,2HMM,1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;";

/// A 126 with K = 3, M = 2 and a distinct sentinel in every slot.
fn sentinel_126() -> String {
    // knots: K+M+2 = 7 values 101..107; weights 201..204; points 301..312;
    // V(0) = 401, V(1) = 402, normal 501..503.
    format!(
        "126,3,2,1,0,0,0,{},{},{},401.,402.,501.,502.,503.;",
        seq_reals(101.0, 7),
        seq_reals(201.0, 4),
        seq_reals(301.0, 12)
    )
}

#[test]
fn curve_126_every_slot_lands_in_place() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let de = b.entity(De::default(), &sentinel_126());
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    assert!(file.warnings.is_empty(), "{:?}", file.warnings);
    let e = file.entry(de as i64).unwrap();
    let c = file.decode::<Curve126>(e).record.unwrap();
    assert_eq!(c.degree, 2);
    assert_eq!((c.planar, c.closed, c.polynomial, c.periodic), (1, 0, 0, 0));
    assert_eq!(c.knots, (101..=107).map(f64::from).collect::<Vec<_>>());
    assert_eq!(c.weights, vec![201.0, 202.0, 203.0, 204.0]);
    assert_eq!(c.points[0], [301.0, 302.0, 303.0]);
    assert_eq!(c.points[3], [310.0, 311.0, 312.0]);
    assert_eq!((c.v0, c.v1), (Some(401.0), Some(402.0)));
    assert_eq!(c.normal, Some([501.0, 502.0, 503.0]));
    assert_eq!(c.extra, 0);
}

#[test]
fn surface_128_non_square_first_index_fastest() {
    // K1 = 3 (4 poles in u), K2 = 2 (3 poles in v), M1 = 2, M2 = 1.
    // Pole (i, j) carries x = 1000 + 10 i + j, weight 2000 + 10 i + j, listed i fastest.
    let mut body = String::from("128,3,2,2,1,0,1,0,0,0,");
    body += &seq_reals(101.0, 3 + 2 + 2); // S knots: 7
    body += ",";
    body += &seq_reals(201.0, 2 + 1 + 2); // T knots: 5
    let mut w = Vec::new();
    let mut p = Vec::new();
    for j in 0..3 {
        for i in 0..4 {
            w.push(format!("{}.", 2000 + 10 * i + j));
            p.push(format!(
                "{}.,{}.,{}.",
                1000 + 10 * i + j,
                5000 + 10 * i + j,
                -(10 * i + j)
            ));
        }
    }
    body += &format!(",{},{},-1.,-2.,-3.,-4.;", w.join(","), p.join(","));
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let de = b.entity(
        De {
            ty: 128,
            ..De::default()
        },
        &body,
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let s = file
        .decode::<Surface128>(file.entry(de as i64).unwrap())
        .record
        .unwrap();
    assert_eq!(s.poles, [4, 3]);
    assert_eq!(s.degree, [2, 1]);
    assert_eq!(s.closed, [0, 1]);
    assert_eq!(s.knots_u, (101..=107).map(f64::from).collect::<Vec<_>>());
    assert_eq!(s.knots_v, (201..=205).map(f64::from).collect::<Vec<_>>());
    for i in 0..4 {
        for j in 0..3 {
            let k = s.index(i, j);
            let tag = (10 * i + j) as f64;
            assert_eq!(s.weights[k], 2000.0 + tag, "w({i},{j})");
            assert_eq!(
                s.points[k],
                [1000.0 + tag, 5000.0 + tag, -tag],
                "p({i},{j})"
            );
        }
    }
    assert_eq!(s.range, Some([-1.0, -2.0, -3.0, -4.0]));
}

#[test]
fn planar_126_without_normal_and_missing_range() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let a = b.entity(
        De::default(),
        "126,1,1,1,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.;",
    );
    let c = b.entity(
        De::default(),
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.;",
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let ca = file
        .decode::<Curve126>(file.entry(a as i64).unwrap())
        .record
        .unwrap();
    assert_eq!(ca.planar, 1);
    assert_eq!((ca.v0, ca.v1, ca.normal), (Some(0.0), Some(1.0), None));
    let cc = file
        .decode::<Curve126>(file.entry(c as i64).unwrap())
        .record
        .unwrap();
    assert_eq!((cc.v0, cc.v1, cc.normal), (None, None, None));
    assert_eq!(cc.points[1], [1.0, 0.0, 0.0]);
}

#[test]
fn exponents_comments_and_blanks() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let lines = vec![
        "126, 1 ,1,0,0,1,0, 0.D0,.0,1.d0,1.E0 ,1.,5.,".to_owned(),
        "-3.905D2,2.1d-1,.5,1.0D0,1,0.E+000,0.,1.; this is a comment, 7,8".to_owned(),
        "more comment text counted in field 14".to_owned(),
    ];
    let de = b.entity_lines(De::default(), &lines);
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let d = file.decode::<Curve126>(file.entry(de as i64).unwrap());
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let c = d.record.unwrap();
    assert_eq!(c.knots, vec![0.0, 0.0, 1.0, 1.0]);
    assert_eq!(c.weights, vec![1.0, 5.0]);
    assert_eq!(c.points, vec![[-390.5, 0.21, 0.5], [1.0, 1.0, 0.0]]);
    assert_eq!((c.v0, c.v1), (Some(0.0), Some(1.0)));
}

#[test]
fn custom_delimiters_and_hollerith_with_delimiters() {
    // Parameter delimiter '/', record delimiter '#'; strings hold both and the defaults.
    let global = "1H//1H#/9Ha/b#c,d;e/8Hfile.igs/////////1./6/1HM////1.E-6//////#";
    let mut b = Builder::new(global).with_delims('/', '#');
    let de = b.entity(
        De::default(),
        "126/1/1/0/0/1/0/0./0./1./1./1./1./0./0./0./1.E3/0./0./0./1.#",
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let g = &file.global;
    assert_eq!((g.param_delimiter, g.record_delimiter), ('/', '#'));
    assert_eq!(g.product_id_sender.as_deref(), Some("a/b#c,d;e"));
    assert_eq!(g.file_name.as_deref(), Some("file.igs"));
    assert_eq!(g.model_scale, Some(1.0));
    assert_eq!(g.units_flag, Some(6));
    assert_eq!(g.units_name.as_deref(), Some("M"));
    assert_eq!(g.resolution, Some(1e-6));
    let c = file
        .decode::<Curve126>(file.entry(de as i64).unwrap())
        .record
        .unwrap();
    assert_eq!(c.points[1], [1000.0, 0.0, 0.0]);

    // The form `1H/,1H#,` (a comma after the declarations) is tolerated with a warning.
    let mut b = Builder::new("1H/,1H#,4Hname/#").with_delims('/', '#');
    b.entity(
        De::default(),
        "126/1/1/0/0/1/0/0./0./1./1./1./1./0./0./0./1./0./0./0./1.#",
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    assert_eq!(file.global.product_id_sender.as_deref(), Some("name"));
    assert!(file.warnings.iter().any(|w| w.code == "delimiter_form"));
}

#[test]
fn global_forms_explicit_defaults_and_spanning_hollerith() {
    // `1H,,1H;,` (explicit defaults) and a Hollerith string that continues on the next record.
    let long = "x,;".repeat(30); // 90 characters holding both delimiters
    let global = format!("1H,,1H;,90H{long},8Hfile.igs,,,,,,,,,1.,1,4HINCH;");
    let mut b = Builder::new(&global);
    b.entity(
        De::default(),
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.;",
    );
    let text = b.build();
    assert!(text.lines().filter(|l| l.as_bytes()[72] == b'G').count() >= 2);
    let file = iges::parse(&text).unwrap();
    assert_eq!(
        file.global.product_id_sender.as_deref(),
        Some(long.as_str())
    );
    assert_eq!(file.global.units_flag, Some(1));
    assert_eq!(file.global.units_name.as_deref(), Some("INCH"));
    assert_eq!(file.global.integer_bits, None);
}

#[test]
fn occt_global_section() {
    let mut b = Builder::new("");
    b.global = OCCT_GLOBAL.iter().map(|s| s.to_string()).collect();
    b.entity(
        De::default(),
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.;",
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let g = &file.global;
    assert_eq!((g.param_delimiter, g.record_delimiter), (',', ';'));
    assert_eq!(
        g.product_id_sender.as_deref(),
        Some("Open CASCADE IGES processor 7.4")
    );
    assert_eq!(g.file_name.as_deref(), Some("Filename.iges"));
    assert_eq!(g.native_system_id.as_deref(), Some("Open CASCADE 7.4"));
    assert_eq!(g.integer_bits, Some(32));
    assert_eq!(g.double_digits, Some(15));
    assert_eq!(g.product_id_receiver, None);
    assert_eq!(g.model_scale, Some(1.0));
    assert_eq!(g.units_flag, Some(2));
    assert_eq!(g.units_name.as_deref(), Some("MM"));
    assert_eq!(g.line_weight_gradations, Some(1));
    assert_eq!(g.max_line_width, Some(0.01));
    assert_eq!(g.date.as_deref(), Some("20260730.183948"));
    assert_eq!(g.resolution, Some(0.0026726));
    assert_eq!(g.max_coordinate, Some(158.75));
    assert_eq!(
        (g.author.as_deref(), g.organization.as_deref()),
        (None, None)
    );
    assert_eq!(g.version_flag, Some(11));
    assert_eq!(g.version_name(), Some("IGES 5.3"));
    assert_eq!(g.drafting_standard, Some(0));
    assert_eq!(g.modified_date.as_deref(), Some("20260730.183948"));
    assert_eq!(g.application_protocol, None);
}

#[test]
fn euclid_excerpt() {
    // spec.md a.5: a EUCLID-written 126 at DE 21, P lines 41-45. Lines 41, 42 and 45 are
    // quoted verbatim; lines 43-44 (elided in the quote) hold the three middle poles,
    // filled in here with values of the same shape. Ten filler entities (DE 1-19, 4 P
    // lines each, 3 of them comment lines counted in field 14) put the 126 at DE 21, P 41.
    let mut b = Builder::new(DEFAULT_GLOBAL);
    for k in 0..10 {
        let lines = vec![
            format!("116,{k}.,0.,0.,0;"),
            "comment line".to_owned(),
            "another".to_owned(),
            String::new(),
        ];
        b.entity_lines(
            De {
                ty: 116,
                ..De::default()
            },
            &lines,
        );
    }
    let lines: Vec<String> = [
        "126,3,3,0,0,1,0,0.E+000,0.E+000,0.E+000,0.E+000,1.,1.,1.,1.,1.,",
        "1.,1.,1.,-4.648701E-003,-2.168055E-002,1.462853E-002,",
        "-4.1E-003,-2.0E-002,1.47E-002,-3.2E-003,-1.9E-002,1.475E-002,",
        "-2.5E-003,-1.8E-002,",
        "1.476733E-002,0.E+000,1.,0.E+000,0.E+000,1.;",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let de = b.entity_lines(De::default(), &lines);
    assert_eq!(de, 21);
    let text = b.build();
    // The quoted record shape: back-pointer and sequence in columns 66-80.
    let line41 = text.lines().find(|l| l.ends_with("P0000041")).unwrap();
    assert_eq!(&line41[64..], "      21P0000041");
    let file = iges::parse(&text).unwrap();
    let e = file.entry(21).unwrap();
    assert_eq!(e.parameter_pointer, 41);
    let c = file.decode::<Curve126>(e).record.unwrap();
    assert_eq!(c.degree, 3);
    assert_eq!(c.knots, vec![0., 0., 0., 0., 1., 1., 1., 1.]);
    assert_eq!(c.weights, vec![1.; 4]);
    assert_eq!(c.points[0], [-4.648701e-3, -2.168055e-2, 1.462853e-2]);
    assert_eq!(c.points[3], [-2.5e-3, -1.8e-2, 1.476733e-2]);
    assert_eq!((c.v0, c.v1), (Some(0.0), Some(1.0)));
    assert_eq!(c.normal, Some([0.0, 0.0, 1.0]));
    // The fillers read cleanly as raw entities, comment lines included.
    let p = file.parameters(file.entry(19).unwrap()).unwrap();
    assert_eq!(p.len(), 5);
    assert_eq!(p.real(1).unwrap(), 9.0);
    assert!(p.warnings.is_empty());
}

#[test]
fn transform_124_and_other_entities_kept_raw() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let t = b.entity(
        De {
            ty: 124,
            ..De::default()
        },
        "124,0.,-1.,0.,10.,1.,0.,0.,20.,0.,0.,1.,30.;",
    );
    let c = b.entity(
        De {
            transform: t as i64,
            ..De::default()
        },
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.;",
    );
    let s = b.entity(
        De {
            ty: 402,
            form: 7,
            ..De::default()
        },
        "402,2,1,3;",
    );
    let h = b.entity(
        De {
            ty: 406,
            form: 15,
            ..De::default()
        },
        "406,1,5HPART1;",
    );
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let tr = file
        .decode::<Transform124>(file.entry(t as i64).unwrap())
        .record
        .unwrap();
    assert_eq!(tr.apply([1.0, 2.0, 3.0]), [8.0, 21.0, 33.0]);
    assert_eq!(file.entry(c as i64).unwrap().transform, t as i64);
    let p = file.parameters(file.entry(s as i64).unwrap()).unwrap();
    assert_eq!((p.entity_type, p.form, p.len()), (402, 7, 4));
    let p = file.parameters(file.entry(h as i64).unwrap()).unwrap();
    assert_eq!(p.string(2), Some("PART1"));
}

#[test]
fn directory_entry_fields() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    b.entity(
        De {
            status: "01010500",
            label: "BSPL",
            form: 2,
            ..De::default()
        },
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.;",
    );
    // Overwrite some fields by hand: structure 1 (tolerated), color 3, subscript 42.
    b.d[0].replace_range(16..24, &format!("{:>8}", 1));
    b.d[1].replace_range(16..24, &format!("{:>8}", 3));
    b.d[1].replace_range(64..72, &format!("{:>8}", 42));
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let e = file.entries[0].as_ref().unwrap();
    assert_eq!(
        (e.pointer, e.entity_type, e.parameter_pointer, e.form),
        (1, 126, 1, 2)
    );
    assert_eq!((e.structure, e.color, e.subscript), (1, 3, 42));
    assert_eq!(e.parameter_line_count, 1);
    assert_eq!(e.label, "BSPL");
    let st = e.status;
    assert_eq!(
        (st.blank, st.subordinate, st.use_flag, st.hierarchy),
        (1, 1, 5, 0)
    );
}

fn good_file() -> String {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    b.entity(De::default(), &sentinel_126());
    b.build()
}

#[test]
fn crlf_and_short_lines_tolerated() {
    let text = good_file();
    let crlf = text.replace('\n', "\r\n");
    let f = iges::parse(&crlf).unwrap();
    assert!(f.warnings.iter().any(|w| w.code == "crlf"));
    let c = f.decode::<Curve126>(f.entry(1).unwrap()).record.unwrap();
    assert_eq!(c.normal, Some([501.0, 502.0, 503.0]));
    // Short S/G/T lines: trailing blanks of the data columns removed.
    let short: String = text
        .lines()
        .map(|l| {
            if l.as_bytes()[72] == b'S' || l.as_bytes()[72] == b'T' {
                format!("{} {}\n", l[..72].trim_end(), &l[72..])
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let f = iges::parse(&short).unwrap();
    assert!(f.warnings.iter().any(|w| w.code == "short_line"));
    assert_eq!(f.start, "nurbsx test file");
}

#[test]
fn structural_errors_are_located() {
    let text = good_file();
    let lines: Vec<&str> = text.lines().collect();
    // Truncated: no T record.
    let truncated = lines[..lines.len() - 1].join("\n");
    let e = iges::parse(&truncated).unwrap_err();
    assert_eq!(e.kind, ErrorKind::MissingSection('T'));
    // Wrong order: a D record after the P records.
    let n = lines.len();
    let mut swapped: Vec<&str> = lines.clone();
    swapped.swap(n - 2, 3); // first D record <-> last P record
    let e = iges::parse(&swapped.join("\n")).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::SectionOrder { .. }), "{e}");
    assert!(e.line.is_some());
    // No D section at all.
    let no_d: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| l.as_bytes()[72] != b'D')
        .collect();
    let e = iges::parse(&no_d.join("\n")).unwrap_err();
    assert_eq!(e.kind, ErrorKind::MissingSection('D'));
    // A garbled record (no section letter).
    let mut garbled = lines.clone();
    garbled[2] = "this line is not an IGES record at all";
    let e = iges::parse(&garbled.join("\n")).unwrap_err();
    assert_eq!((e.kind.clone(), e.line), (ErrorKind::BadRecord, Some(3)));
    // Odd number of D records.
    let mut odd = lines.clone();
    odd.remove(3);
    let e = iges::parse(&odd.join("\n")).unwrap_err();
    assert_eq!(e.kind, ErrorKind::OddDirectory(1));
}

#[test]
fn entity_errors_are_located_and_do_not_stop_others() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let good1 = b.entity(De::default(), &sentinel_126());
    // A garbled knot on the second line of the record.
    let bad = b.entity(De::default(), &sentinel_126().replace("310.0", "1.52.3"));
    // K = 2^31 - 1 with a handful of parameters: refused before allocating.
    let huge = b.entity(De::default(), "126,2147483647,3,0,0,1,0,0.,0.,1.;");
    let good2 = b.entity(De::default(), &sentinel_126());
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    for de in [good1, good2] {
        let c = file
            .decode::<Curve126>(file.entry(de as i64).unwrap())
            .record
            .unwrap();
        assert_eq!(c.weights, vec![201.0, 202.0, 203.0, 204.0]);
    }
    let e = file
        .decode::<Curve126>(file.entry(bad as i64).unwrap())
        .record
        .unwrap_err();
    assert_eq!(e.de, Some(bad));
    assert_eq!(e.section, 'P');
    // The record was split at 64 columns: find where "1.52.3" actually is.
    let (seq, col) = text
        .lines()
        .filter(|l| l.as_bytes()[72] == b'P')
        .find_map(|l| {
            l.find("1.52.3")
                .map(|c| (l[73..].trim().parse::<usize>().unwrap(), c + 1))
        })
        .unwrap();
    assert_eq!((e.sequence, e.column), (seq, Some(col)));
    assert!(matches!(e.kind, ErrorKind::BadParameter { .. }), "{e}");
    let e = file
        .decode::<Curve126>(file.entry(huge as i64).unwrap())
        .record
        .unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Truncated { .. }), "{e}");
    assert_eq!(e.de, Some(huge));
}

#[test]
fn pointer_and_hollerith_errors() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    b.entity(De::default(), &sentinel_126());
    let h = b.entity(
        De {
            ty: 406,
            ..De::default()
        },
        "406,1,80HPART;",
    );
    b.entity(De::default(), &sentinel_126());
    // Parameter pointer of the last entry pointing far beyond the P section.
    let last_d1 = b.d.len() - 2;
    b.d[last_d1].replace_range(8..16, &format!("{:>8}", 999));
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let e = file.parameters(file.entry(h as i64).unwrap()).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::HollerithTooLong { declared: 80, .. }),
        "{e}"
    );
    assert_eq!((e.section, e.de, e.column), ('P', Some(h), Some(7)));
    let e = file.parameters(file.entry(5).unwrap()).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::BadPointer { value: 999, .. }),
        "{e}"
    );
    assert_eq!((e.section, e.sequence, e.de), ('D', 5, Some(5)));
    // Pointers to nothing.
    assert!(file.entry(2).is_none());
    assert!(file.entry(99).is_none());

    // A back-pointer naming another entity.
    let mut b = Builder::new(DEFAULT_GLOBAL);
    b.entity(De::default(), &sentinel_126());
    b.p[0].replace_range(65..72, &format!("{:>7}", 3));
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let e = file.parameters(file.entry(1).unwrap()).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::BackPointer { expected: 1, .. }),
        "{e}"
    );
    assert_eq!((e.section, e.sequence, e.column), ('P', 1, Some(66)));
}

#[test]
fn unterminated_and_bad_directory_field() {
    let mut b = Builder::new(DEFAULT_GLOBAL);
    b.entity(
        De::default(),
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.",
    );
    b.entity(De::default(), &sentinel_126());
    b.d[3].replace_range(32..40, "     1x2"); // form number field garbled
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let e = file.parameters(file.entry(1).unwrap()).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Unterminated(';'));
    let e = file.entries[1].as_ref().unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::BadField { field: 15, .. }),
        "{e}"
    );
    assert_eq!(
        (e.section, e.sequence, e.column, e.de),
        ('D', 4, Some(33), Some(3))
    );
}

#[test]
fn terminate_counts_checked() {
    let text: String = good_file()
        .lines()
        .map(|l| {
            if l.ends_with("T0000001") {
                format!("{}P    999{}\n", &l[..24], &l[32..])
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let file = iges::parse(&text).unwrap();
    assert!(file.warnings.iter().any(|w| w.code == "terminate_count"));
    assert_eq!(file.terminate_counts.map(|c| c[3]), Some(999));
    let _ = rec;
}

#[test]
fn missing_start_section_and_global_field_13_missing() {
    // No S records; Global parameter 13 (model scale) empty; a malformed parameter 16.
    let global = ",,4Htest,8Hfile.igs,,,,,,,,,,2,2HMM,x1,,,1.E-7,,,,11,0,;";
    let mut b = Builder::new(global);
    b.start.clear();
    b.entity(De::default(), &sentinel_126());
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    assert!(file.warnings.iter().any(|w| w.code == "missing_start"));
    let w = file
        .warnings
        .iter()
        .find(|w| w.code == "global_field")
        .unwrap();
    assert_eq!((w.section, w.sequence), ('G', 1));
    assert!(w.message.contains("16"), "{}", w.message);
    assert_eq!(file.global.model_scale, None);
    assert_eq!(file.global.units_flag, Some(2));
    assert_eq!(file.global.line_weight_gradations, None);
    assert_eq!(file.global.resolution, Some(1e-7));
    // A malformed units flag is fatal: coordinates depend on it.
    let mut b = Builder::new(",,4Htest,8Hfile.igs,,,,,,,,,1.,MM,2HMM;");
    b.entity(De::default(), &sentinel_126());
    let text = b.build();
    let e = iges::parse(&text).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::BadParameter { index: 14, .. }),
        "{e}"
    );
    assert_eq!((e.section, e.sequence), ('G', 1));
    assert_eq!(
        e.column,
        Some(text.lines().nth(1).unwrap().find(",MM,").unwrap() + 2)
    );
}

/// The pointer entities decode by their declarations: every field lands in place, the
/// pointer walk lists what the declarations call pointers, and a record shorter than its
/// counts is an error naming them.
#[test]
fn pointer_entities_decode_by_their_declarations() {
    use nurbsx_parsers::iges::records::{
        CompositeCurve102, CurveOnSurface142, Edge, EdgeList504, Face510, Loop508, LoopEdge,
        TrimmedSurface144,
    };
    let ty = |ty| De {
        ty,
        ..De::default()
    };
    let mut b = Builder::new(DEFAULT_GLOBAL);
    let c1 = b.entity(De::default(), &sentinel_126()); // D1
    let c2 = b.entity(De::default(), &sentinel_126()); // D3
    let comp = b.entity(ty(102), "102,2,1,3;"); // D5
    let cos = b.entity(ty(142), "142,1,31,5,,2;"); // D7
    let trim = b.entity(ty(144), "144,31,1,2,7,7,7;"); // D9
    let edges = b.entity(ty(504), "504,2,1,41,1,41,2,3,41,2,41,1;"); // D11
    let lp = b.entity(ty(508), "508,2,0,11,1,1,1,0,5,0,11,2,0,2,1,1,0,3;"); // D13
    let face = b.entity(ty(510), "510,31,1,1,13;"); // D15
    let short = b.entity(ty(102), "102,3,1;"); // D17
    let negative = b.entity(ty(102), "102,-1;"); // D19
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let entry = |de: usize| file.entry(de as i64).unwrap();
    assert_eq!((c1, c2), (1, 3));
    assert_eq!(
        file.decode::<CompositeCurve102>(entry(comp))
            .record
            .unwrap(),
        CompositeCurve102 {
            members: vec![1, 3]
        }
    );
    assert_eq!(
        file.decode::<CurveOnSurface142>(entry(cos)).record.unwrap(),
        CurveOnSurface142 {
            creation: 1,
            surface: 31,
            parameter_curve: 5,
            model_curve: 0,
            preferred: 2
        }
    );
    assert_eq!(
        file.decode::<TrimmedSurface144>(entry(trim))
            .record
            .unwrap(),
        TrimmedSurface144 {
            surface: 31,
            outer_given: 1,
            outer: 7,
            inner: vec![7, 7]
        }
    );
    assert_eq!(
        file.decode::<EdgeList504>(entry(edges)).record.unwrap(),
        EdgeList504 {
            edges: vec![
                Edge {
                    curve: 1,
                    start: (41, 1),
                    end: (41, 2)
                },
                Edge {
                    curve: 3,
                    start: (41, 2),
                    end: (41, 1)
                },
            ]
        }
    );
    assert_eq!(
        file.decode::<Loop508>(entry(lp)).record.unwrap(),
        Loop508 {
            edges: vec![
                LoopEdge {
                    kind: 0,
                    edge: 11,
                    index: 1,
                    orientation: 1,
                    parameter_curves: vec![(0, 5)]
                },
                LoopEdge {
                    kind: 0,
                    edge: 11,
                    index: 2,
                    orientation: 0,
                    parameter_curves: vec![(1, 1), (0, 3)]
                },
            ]
        }
    );
    assert_eq!(
        file.decode::<Face510>(entry(face)).record.unwrap(),
        Face510 {
            surface: 31,
            outer_first: 1,
            loops: vec![13]
        }
    );
    // The pointer walk: names, values and the types each field may name.
    let refs = file.references(entry(lp)).unwrap().unwrap();
    let pointers: Vec<(&str, i64)> = refs.iter().map(|&(n, p, _)| (n, p)).collect();
    assert_eq!(
        pointers,
        vec![
            ("EDGE", 11),
            ("CURV", 5),
            ("EDGE", 11),
            ("CURV", 1),
            ("CURV", 3)
        ]
    );
    assert_eq!(refs[0].2, &[504, 502]);
    let refs = file.references(entry(cos)).unwrap().unwrap();
    assert_eq!(
        refs.iter().map(|&(n, p, _)| (n, p)).collect::<Vec<_>>(),
        vec![("SPTR", 31), ("BPTR", 5)]
    );
    assert!(file.references(entry(c1)).unwrap().unwrap().is_empty());
    // Arity from the declaration: N = 3 needs 4 parameters, the record holds 2.
    let e = file
        .decode::<CompositeCurve102>(entry(short))
        .record
        .unwrap_err();
    assert!(
        matches!(&e.kind, ErrorKind::Truncated { what, needed: 4, present: 2 } if what == "102 with N = 3"),
        "{e}"
    );
    assert_eq!((e.section, e.de), ('P', Some(short)));
    let e = file
        .decode::<CompositeCurve102>(entry(negative))
        .record
        .unwrap_err();
    assert!(matches!(e.kind, ErrorKind::OutOfRange(_)), "{e}");
    // A record of another type is refused by name.
    let e = file.decode::<Face510>(entry(comp)).record.unwrap_err();
    assert!(
        matches!(
            e.kind,
            ErrorKind::WrongEntity {
                found: 102,
                expected: 510
            }
        ),
        "{e}"
    );
}

/// The record split and the directory scan poll the caller's stop signal every
/// `SCAN_POLL` lines or entries: never firing, the file parses as without a signal, polled
/// about once per `SCAN_POLL` lines; firing at a poll, the parse ends there with `Stopped`.
#[test]
fn parse_stops_when_its_signal_fires() {
    use nurbsx_parsers::{Limits, Stop, stop::SCAN_POLL};
    use std::sync::atomic::{AtomicUsize, Ordering};
    let mut b = Builder::new(DEFAULT_GLOBAL);
    for k in 0..10_000 {
        b.entity(
            De {
                ty: 116,
                ..De::default()
            },
            &format!("116,{k}.,0.,0.,0;"),
        );
    }
    let text = b.build();
    let lines = text.lines().count();
    let polls = AtomicUsize::new(0);
    let never = || {
        polls.fetch_add(1, Ordering::Relaxed);
        false
    };
    let file = iges::parse_with(&text, &Limits::default(), Stop::new(&never)).unwrap();
    assert_eq!(file.entries.len(), 10_000);
    assert_eq!(file.entries, iges::parse(&text).unwrap().entries);
    // Lines, then directory entries (half the D lines).
    let expected = lines / SCAN_POLL + 10_000 / SCAN_POLL;
    assert_eq!(polls.load(Ordering::Relaxed), expected);
    for fire_at in [1, expected] {
        let polls = AtomicUsize::new(0);
        let fire = || polls.fetch_add(1, Ordering::Relaxed) + 1 >= fire_at;
        let e = iges::parse_with(&text, &Limits::default(), Stop::new(&fire)).unwrap_err();
        assert_eq!(e.kind, ErrorKind::Stopped);
        assert_eq!(polls.load(Ordering::Relaxed), fire_at);
    }
}
