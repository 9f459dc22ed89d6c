//! The analytic curve and surface entities (IGES 5.3 sections 4.3-4.19, 4.50-4.54):
//! every parameter lands in its field, and a record with too few parameters (or a count out
//! of range) is an error located at the entity's P record with its DE pointer. Files are
//! built by `iges_support`, which formats every record by hand.
#![allow(clippy::cast_possible_wrap)]
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod iges_support;

use iges_support::{Builder, De};
use nurbsx_parsers::iges::{self, ErrorKind, IgesFile, ParseError, records::*};

const GLOBAL: &str = ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,2,2HMM,1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;";

fn de(ty: i64, form: i64) -> De<'static> {
    De {
        ty,
        form,
        ..De::default()
    }
}

/// Builds a file of `(type, form, parameters)` entities; returns its text.
fn file_of(entities: &[(i64, i64, String)]) -> String {
    let mut b = Builder::new(GLOBAL);
    for (ty, form, params) in entities {
        b.entity(de(*ty, *form), params);
    }
    b.build()
}

fn decode<R: Entity>(file: &IgesFile<'_>, pointer: usize) -> Result<R, ParseError> {
    file.decode::<R>(file.entry(pointer as i64).unwrap()).record
}

/// `n` reals `base, base + 1, ..` as parameters.
fn reals(base: f64, n: usize) -> Vec<String> {
    (0..n).map(|k| format!("{:.1}", base + k as f64)).collect()
}

fn params(ty: i64, values: &[String]) -> String {
    format!("{ty},{};", values.join(","))
}

#[test]
fn curves_decode_in_place() {
    let arc = params(100, &reals(1.0, 7));
    let conic = params(104, &reals(11.0, 11));
    let copious1 = format!("106,1,3,5.,{};", reals(21.0, 6).join(","));
    let copious2 = format!("106,2,2,{};", reals(31.0, 6).join(","));
    let copious3 = format!("106,3,1,{};", reals(41.0, 6).join(","));
    let line = params(110, &reals(51.0, 6));
    // Two segments: breakpoints 0, 1, 3; coefficients 101..124; terminate 201..212.
    let spline = format!(
        "112,3,2,3,2,0.,1.,3.,{},{};",
        reals(101.0, 24).join(","),
        reals(201.0, 12).join(",")
    );
    let text = file_of(&[
        (100, 0, arc),
        (104, 2, conic),
        (106, 11, copious1),
        (106, 12, copious2),
        (106, 13, copious3),
        (110, 1, line),
        (112, 0, spline),
    ]);
    let file = iges::parse(&text).unwrap();
    let a: CircularArc100 = decode(&file, 1).unwrap();
    assert_eq!(
        a,
        CircularArc100 {
            zt: 1.0,
            centre: [2.0, 3.0],
            start: [4.0, 5.0],
            end: [6.0, 7.0]
        }
    );
    let c: ConicArc104 = decode(&file, 3).unwrap();
    assert_eq!(c.coefficients, [11.0, 12.0, 13.0, 14.0, 15.0, 16.0]);
    assert_eq!(
        (c.zt, c.start, c.end, c.form),
        (17.0, [18.0, 19.0], [20.0, 21.0], 2)
    );
    let d: CopiousData106 = decode(&file, 5).unwrap();
    assert_eq!(
        d.points,
        vec![[21.0, 22.0, 5.0], [23.0, 24.0, 5.0], [25.0, 26.0, 5.0]]
    );
    assert_eq!((d.ip, d.form), (1, 11));
    let d: CopiousData106 = decode(&file, 7).unwrap();
    assert_eq!(d.points, vec![[31.0, 32.0, 33.0], [34.0, 35.0, 36.0]]);
    let d: CopiousData106 = decode(&file, 9).unwrap();
    assert_eq!(
        (d.points.clone(), d.vectors.clone()),
        (vec![[41.0, 42.0, 43.0]], vec![[44.0, 45.0, 46.0]])
    );
    let l: Line110 = decode(&file, 11).unwrap();
    assert_eq!(
        (l.start, l.end, l.form),
        ([51.0, 52.0, 53.0], [54.0, 55.0, 56.0], 1)
    );
    let s: SplineCurve112 = decode(&file, 13).unwrap();
    assert_eq!((s.ctype, s.continuity, s.ndim), (3, 2, 3));
    assert_eq!(s.breakpoints, vec![0.0, 1.0, 3.0]);
    assert_eq!(s.segments.len(), 2);
    assert_eq!(s.segments[0][0], [101.0, 102.0, 103.0, 104.0]);
    assert_eq!(s.segments[0][2], [109.0, 110.0, 111.0, 112.0]);
    assert_eq!(s.segments[1][1], [117.0, 118.0, 119.0, 120.0]);
    assert_eq!(s.terminate[2], [209.0, 210.0, 211.0, 212.0]);
}

#[test]
fn surfaces_decode_in_place() {
    // 114 with M = 2, N = 1: TU 0,1,2; TV 0,5; rows of (N + 1) = 2 patches of 48, the
    // second of each row arbitrary (999), then the arbitrary row M + 1.
    let mut coeffs = Vec::new();
    for i in 0..2 {
        coeffs.extend(reals(1000.0 * f64::from(i + 1), 48));
        coeffs.extend(std::iter::repeat_n("999.".to_owned(), 48));
    }
    coeffs.extend(std::iter::repeat_n("999.".to_owned(), 96));
    let spline = format!("114,3,1,2,1,0.,1.,2.,0.,5.,{};", coeffs.join(","));
    let text = file_of(&[
        (108, 1, "108,0.,0.,1.,2.,7,1.,2.,3.,4.;".to_owned()),
        (114, 0, spline),
        (118, 1, "118,21,23,1,0;".to_owned()),
        (120, 0, "120,25,27,0.5,1.5;".to_owned()),
        (122, 0, "122,29,1.,2.,3.;".to_owned()),
        (116, 0, "116,1.,2.,3.;".to_owned()),
        (123, 0, "123,0.,0.,1.;".to_owned()),
        (190, 1, "190,11,13,13;".to_owned()),
        (192, 0, "192,11,13,2.5;".to_owned()),
        (194, 1, "194,11,13,2.5,30.,13;".to_owned()),
        (196, 0, "196,11,4.;".to_owned()),
        (198, 1, "198,11,13,5.,1.,13;".to_owned()),
    ]);
    let file = iges::parse(&text).unwrap();
    let p: Plane108 = decode(&file, 1).unwrap();
    assert_eq!(
        (p.coefficients, p.boundary, p.symbol, p.size, p.form),
        ([0.0, 0.0, 1.0, 2.0], 7, [1.0, 2.0, 3.0], 4.0, 1)
    );
    let s: SplineSurface114 = decode(&file, 3).unwrap();
    assert_eq!(
        (s.breakpoints_u.clone(), s.breakpoints_v.clone()),
        (vec![0.0, 1.0, 2.0], vec![0.0, 5.0])
    );
    assert_eq!(s.patches.len(), 2);
    assert_eq!(s.patches[0][0][0], 1000.0);
    assert_eq!(s.patches[0][2][15], 1047.0);
    assert_eq!(s.patches[1][1][0], 2016.0);
    let r: RuledSurface118 = decode(&file, 5).unwrap();
    assert_eq!(
        (r.first, r.second, r.reversed, r.developable, r.form),
        (21, 23, 1, 0, 1)
    );
    let v: Revolution120 = decode(&file, 7).unwrap();
    assert_eq!((v.axis, v.generatrix, v.angles), (25, 27, [0.5, 1.5]));
    let t: TabulatedCylinder122 = decode(&file, 9).unwrap();
    assert_eq!((t.directrix, t.end), (29, [1.0, 2.0, 3.0]));
    assert_eq!(
        decode::<Point116>(&file, 11).unwrap().point,
        [1.0, 2.0, 3.0]
    );
    assert_eq!(
        decode::<Direction123>(&file, 13).unwrap().direction,
        [0.0, 0.0, 1.0]
    );
    assert_eq!(
        decode::<PlaneSurface190>(&file, 15).unwrap(),
        PlaneSurface190 {
            location: 11,
            normal: 13,
            reference: 13,
            form: 1
        }
    );
    let c: Cylinder192 = decode(&file, 17).unwrap();
    assert_eq!(
        (c.location, c.axis, c.radius, c.reference),
        (11, 13, 2.5, 0)
    );
    let k: Cone194 = decode(&file, 19).unwrap();
    assert_eq!(
        (k.radius, k.semi_angle_degrees, k.reference, k.form),
        (2.5, 30.0, 13, 1)
    );
    let s: Sphere196 = decode(&file, 21).unwrap();
    assert_eq!((s.location, s.radius, s.axis, s.reference), (11, 4.0, 0, 0));
    let t: Torus198 = decode(&file, 23).unwrap();
    assert_eq!((t.radii, t.reference), ([5.0, 1.0], 13));
    // The pointer walk follows the declarations: 120's axis and generatrix, 190's point and
    // directions.
    let refs = file.references(file.entry(7).unwrap()).unwrap().unwrap();
    assert_eq!(
        refs.iter().map(|r| (r.0, r.1)).collect::<Vec<_>>(),
        vec![("L", 25), ("C", 27)]
    );
    let refs = file.references(file.entry(15).unwrap()).unwrap().unwrap();
    assert_eq!(refs.len(), 3);
}

/// Each entity with one parameter too few: a located error naming the entity, never a
/// record with a made-up value; and counts out of range.
#[test]
fn short_records_and_bad_counts_are_located_errors() {
    let cases: Vec<(i64, String)> = vec![
        (100, params(100, &reals(1.0, 6))),
        (104, params(104, &reals(1.0, 10))),
        (106, format!("106,2,3,{};", reals(1.0, 8).join(","))),
        (106, "106,4,1,1.,2.;".to_owned()),
        (110, params(110, &reals(1.0, 5))),
        (
            112,
            format!("112,3,2,3,1,0.,1.,{};", reals(1.0, 23).join(",")),
        ),
        (112, "112,3,2,3,0,0.;".to_owned()),
        (
            114,
            format!("114,3,1,1,1,0.,1.,0.,1.,{};", reals(1.0, 95).join(",")),
        ),
        (114, "114,3,1,0,1,0.,0.,1.;".to_owned()),
        (108, "108,0.,0.,1.,2.,0,1.,2.;".to_owned()),
        (118, "118,1,3,0;".to_owned()),
        (120, "120,1,3,0.;".to_owned()),
        (122, "122,1,2.,3.;".to_owned()),
        (116, "116,1.,2.;".to_owned()),
        (123, "123,1.,2.;".to_owned()),
        (190, "190,1;".to_owned()),
        (192, "192,1,3;".to_owned()),
        (194, "194,1,3,2.;".to_owned()),
        (196, "196,1;".to_owned()),
        (198, "198,1,3,5.;".to_owned()),
    ];
    let entities: Vec<(i64, i64, String)> = cases.iter().map(|(t, p)| (*t, 0, p.clone())).collect();
    let text = file_of(&entities);
    let file = iges::parse(&text).unwrap();
    for (k, (ty, p)) in cases.iter().enumerate() {
        let pointer = 2 * k + 1;
        let entry = file.entry(pointer as i64).unwrap();
        let e = match ty {
            100 => file.decode::<CircularArc100>(entry).record.err(),
            104 => file.decode::<ConicArc104>(entry).record.err(),
            106 => file.decode::<CopiousData106>(entry).record.err(),
            108 => file.decode::<Plane108>(entry).record.err(),
            110 => file.decode::<Line110>(entry).record.err(),
            112 => file.decode::<SplineCurve112>(entry).record.err(),
            114 => file.decode::<SplineSurface114>(entry).record.err(),
            116 => file.decode::<Point116>(entry).record.err(),
            118 => file.decode::<RuledSurface118>(entry).record.err(),
            120 => file.decode::<Revolution120>(entry).record.err(),
            122 => file.decode::<TabulatedCylinder122>(entry).record.err(),
            123 => file.decode::<Direction123>(entry).record.err(),
            190 => file.decode::<PlaneSurface190>(entry).record.err(),
            192 => file.decode::<Cylinder192>(entry).record.err(),
            194 => file.decode::<Cone194>(entry).record.err(),
            196 => file.decode::<Sphere196>(entry).record.err(),
            198 => file.decode::<Torus198>(entry).record.err(),
            _ => unreachable!(),
        };
        let e = e.unwrap_or_else(|| panic!("{p} decoded"));
        assert_eq!((e.section, e.de), ('P', Some(pointer)), "{p}: {e}");
        assert!(e.sequence > 0 && e.column.is_some(), "{p}: {e}");
        assert!(
            matches!(
                e.kind,
                ErrorKind::Truncated { .. }
                    | ErrorKind::OutOfRange(_)
                    | ErrorKind::BadParameter { .. }
            ),
            "{p}: {e}"
        );
    }
}
