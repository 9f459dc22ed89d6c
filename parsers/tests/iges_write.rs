//! Writer: exact 80-column layout checked column by column, and write -> parse -> equal.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nurbsx_parsers::iges::{
    self, DirectoryEntry, Global, Status, WriteError,
    records::{Curve126, Surface128, Transform124},
    writer::{ParamWriter, WriteParams, write_with},
};
use nurbsx_parsers::real::NonFiniteReal;
use proptest::prelude::*;

fn global() -> Global {
    Global {
        param_delimiter: ',',
        record_delimiter: ';',
        product_id_sender: Some("nurbsx test, with; delimiters".into()),
        file_name: Some("out.igs".into()),
        native_system_id: Some("nurbsx".into()),
        preprocessor_version: Some("0.1.0".into()),
        integer_bits: Some(32),
        single_max_power: Some(38),
        single_digits: Some(6),
        double_max_power: Some(308),
        double_digits: Some(15),
        model_scale: Some(1.0),
        units_flag: Some(1),
        units_name: Some("INCH".into()),
        line_weight_gradations: Some(1),
        max_line_width: Some(0.01),
        date: Some("20260101.120000".into()),
        resolution: Some(1e-7),
        max_coordinate: Some(1234.5),
        author: Some("a".repeat(100)),
        version_flag: Some(11),
        drafting_standard: Some(0),
        modified_date: Some("20260101.120000".into()),
        ..Global::default()
    }
}

/// An entity to write: its Directory Entry and its typed record.
struct WriteEntity {
    de: DirectoryEntry,
    record: Box<dyn WriteParams>,
}

fn entity(ty: i64, record: impl WriteParams + 'static) -> WriteEntity {
    WriteEntity {
        de: DirectoryEntry {
            entity_type: ty,
            ..DirectoryEntry::default()
        },
        record: Box::new(record),
    }
}

/// A 406 Property entity with one name: a Hollerith string long enough to span lines.
struct Name406(String);

impl WriteParams for Name406 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(406);
        w.int(1);
        w.text(&self.0);
        Ok(())
    }
}

/// Records in, text out.
fn write(start: &str, global: &Global, entities: &[WriteEntity]) -> Result<String, WriteError> {
    let des: Vec<DirectoryEntry> = entities.iter().map(|e| e.de.clone()).collect();
    write_with(start, global, &des, 0, |i, w| {
        entities[i].record.write_params(w)
    })
}

fn curve(points: Vec<[f64; 3]>, weights: Vec<f64>) -> Curve126 {
    let n = points.len();
    let mut knots = vec![0.0; 3];
    for k in 1..n - 2 {
        knots.push(k as f64 / (n - 2) as f64 + 1e-17 * k as f64);
    }
    knots.extend([1.0; 3]);
    Curve126 {
        degree: 2,
        planar: 0,
        closed: 0,
        polynomial: 0,
        periodic: 0,
        knots,
        weights,
        points,
        v0: Some(0.0),
        v1: Some(1.0),
        normal: Some([0.0, 0.0, 1.0]),
        extra: 0,
    }
}

fn surface() -> Surface128 {
    let (nu, nv) = (4, 3);
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            points.push([i as f64 + 0.1, j as f64 * 1.5e-9, (i * j) as f64 / 3.0]);
            weights.push(1.0 + (i + 10 * j) as f64 / 7.0);
        }
    }
    Surface128 {
        degree: [2, 1],
        poles: [nu, nv],
        closed: [0, 0],
        polynomial: 0,
        periodic: [0, 0],
        knots_u: vec![0., 0., 0., 0.5, 1., 1., 1.],
        knots_v: vec![-1., -1., 0.25, 2., 2.],
        weights,
        points,
        range: Some([0., 1., -1., 2.]),
        extra: 0,
    }
}

#[test]
fn layout_is_column_exact_and_reads_back_equal() {
    let c = curve(
        vec![
            [0.1, 0.2, 0.3],
            [1.0 / 3.0, -2e-300, 1e20],
            [5.0, 6.0, 7.0],
            [-0.0, 1.0, 2.0],
        ],
        vec![1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0, 2.5],
    );
    let s = surface();
    let t = Transform124 {
        rows: [[0., -1., 0., 10.], [1., 0., 0., 20.], [0., 0., 1., 30.]],
        form: 0,
    };
    let mut ce = entity(126, c.clone());
    ce.de.transform = 1; // the 124 written first
    ce.de.label = "CURVE1".into();
    ce.de.status = Status {
        use_flag: 5,
        ..Status::default()
    };
    ce.de.subscript = 7;
    let entities = vec![
        entity(124, t),
        ce,
        entity(128, s.clone()),
        entity(406, Name406("x".repeat(150))),
    ];
    let text = write("first line\nsecond line", &global(), &entities).unwrap();

    let lines: Vec<&str> = text.lines().collect();
    let mut counts = [0usize; 5];
    for l in &lines {
        assert_eq!(l.len(), 80, "{l:?}");
        let letter = l.as_bytes()[72];
        let k = b"SGDPT".iter().position(|&c| c == letter).unwrap();
        counts[k] += 1;
        // Sequence numbers: 7 digits, restart per section.
        assert_eq!(l[73..].parse::<usize>().unwrap(), counts[k], "{l}");
        if letter == b'P' {
            assert_eq!(&l[64..65], " ");
            let de: usize = l[65..72].trim().parse().unwrap();
            assert!(de % 2 == 1);
        }
        if letter == b'D' && counts[k] % 2 == 1 {
            assert!(l[64..72].bytes().all(|b| b.is_ascii_digit()), "status {l}");
        }
    }
    assert_eq!(counts[0], 2);
    assert_eq!(counts[2], 8);
    assert_eq!(counts[4], 1);
    let t_line = lines.last().unwrap();
    assert_eq!(
        &t_line[..32],
        format!(
            "S{:7}G{:7}D{:7}P{:7}",
            counts[0], counts[1], counts[2], counts[3]
        )
    );
    // Plain parameters are never split: each P line's data ends with a delimiter.
    for l in lines.iter().filter(|l| l.as_bytes()[72] == b'P') {
        let data = l[..64].trim_end();
        let holl = data.contains("xxx");
        assert!(holl || data.ends_with(',') || data.ends_with(';'), "{l}");
    }
    // D line 3/4 (the curve): fields right-justified in 8 columns.
    let d3 = lines.iter().find(|l| l.ends_with("D0000003")).unwrap();
    assert_eq!(&d3[..8], "     126");
    assert_eq!(&d3[48..56], "       1"); // transform -> DE 1
    assert_eq!(&d3[64..72], "00000500");
    let d4 = lines.iter().find(|l| l.ends_with("D0000004")).unwrap();
    assert_eq!(&d4[56..64], "  CURVE1");
    assert_eq!(&d4[64..72], "       7");

    let file = iges::parse(&text).unwrap();
    assert!(file.warnings.is_empty(), "{:?}", file.warnings);
    assert_eq!(file.start, "first line\nsecond line");
    assert_eq!(file.global, global());
    let e = file.entry(3).unwrap();
    assert_eq!(
        (
            e.transform,
            e.label.as_str(),
            e.status.use_flag,
            e.subscript
        ),
        (1, "CURVE1", 5, 7)
    );
    let c2 = file.decode::<Curve126>(e).record.unwrap();
    assert_eq!(c2, c);
    assert!(c2.points[3][0].is_sign_negative());
    let s2 = file
        .decode::<Surface128>(file.entry(5).unwrap())
        .record
        .unwrap();
    assert_eq!(s2, s);
    let t2 = file
        .decode::<Transform124>(file.entry(1).unwrap())
        .record
        .unwrap();
    assert_eq!(t2.rows, t.rows);
    let p = file.parameters(file.entry(7).unwrap()).unwrap();
    assert_eq!(p.string(2), Some("x".repeat(150).as_str()));
}

#[test]
fn custom_delimiters_written_and_read() {
    let mut g = global();
    g.param_delimiter = '/';
    g.record_delimiter = '#';
    let c = curve(
        vec![[0.0; 3], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
        vec![1.0; 3],
    );
    let text = write("", &g, &[entity(126, c.clone())]).unwrap();
    assert!(text.lines().nth(1).unwrap().starts_with("1H//1H#/"));
    let file = iges::parse(&text).unwrap();
    assert_eq!(file.global, g);
    let c2 = file
        .decode::<Curve126>(file.entry(1).unwrap())
        .record
        .unwrap();
    assert_eq!(c2, c);
}

#[test]
fn non_finite_is_refused() {
    let c = curve(
        vec![[0.0; 3], [f64::NAN, 2.0, 3.0], [4.0, 5.0, 6.0]],
        vec![1.0; 3],
    );
    assert!(write("", &global(), &[entity(126, c.clone())]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Any finite coordinates and weights survive write -> parse bit for bit.
    #[test]
    fn reals_round_trip_bit_exact(bits in proptest::collection::vec(any::<u64>(), 16)) {
        let vals: Vec<f64> = bits.iter().map(|&b| {
            let x = f64::from_bits(b);
            if x.is_finite() { x } else { 1.5 }
        }).collect();
        let points: Vec<[f64; 3]> = (0..4).map(|k| [vals[3 * k], vals[3 * k + 1], vals[3 * k + 2]]).collect();
        let weights: Vec<f64> = vals[12..16].iter().map(|w| w.abs().max(1e-300)).collect();
        let c = curve(points, weights);
        let text = write("", &global(), &[entity(126, c.clone())]).unwrap();
        let file = iges::parse(&text).unwrap();
        let c2 = file.decode::<Curve126>(file.entry(1).unwrap()).record.unwrap();
        for (a, b) in c.points.iter().flatten().zip(c2.points.iter().flatten()) {
            prop_assert_eq!(a.to_bits(), b.to_bits());
        }
        for (a, b) in c.weights.iter().zip(&c2.weights) {
            prop_assert_eq!(a.to_bits(), b.to_bits());
        }
    }
}
