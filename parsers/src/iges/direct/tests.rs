//! The direct reader against the general path (`parameters` + `from_params`): same records,
//! same warnings, same located errors, on random well-formed and damaged 126/128 records.

use super::super::schema::{Curve126, Surface128};
use super::super::{IgesFile, parse};
use super::{Decoded, Scratch};
use proptest::prelude::*;

/// One 80-column record.
fn rec(data: &str, section: char, seq: usize) -> String {
    format!("{data:<72}{section}{seq:>7}\n")
}

/// An IGES file with one entity per `(type, parameter text, line width, declared line
/// count delta)`: the parameter text is cut into P lines of `width` data columns (1-64, so
/// tokens may straddle lines), the DE's line count is off by `delta`.
fn document(delims: Option<(char, char)>, entities: &[(i64, String, usize, i64)]) -> String {
    let mut text = rec("direct reader test", 'S', 1);
    text += &match delims {
        None => rec(",,;", 'G', 1),
        Some((p, r)) => rec(&format!("1H{p}{p}1H{r}{p}{r}"), 'G', 1),
    };
    let mut d = String::new();
    let mut p = String::new();
    let mut pseq = 1usize;
    for (k, (ty, params, width, delta)) in entities.iter().enumerate() {
        let de = 2 * k + 1;
        let chars: Vec<char> = params.chars().collect();
        let lines: Vec<String> = chars
            .chunks((*width).clamp(1, 64))
            .map(|c| c.iter().collect())
            .collect();
        let count = i64::try_from(lines.len()).unwrap() + delta;
        d += &rec(
            &format!("{ty:>8}{pseq:>8}       0       0       0       0       0       000000000"),
            'D',
            de,
        );
        d += &rec(
            &format!("{ty:>8}       0       0{count:>8}       0"),
            'D',
            de + 1,
        );
        for line in lines {
            p += &format!("{line:<64} {de:>7}P{pseq:>7}\n");
            pseq += 1;
        }
    }
    let nd = 2 * entities.len();
    text + &d + &p + &rec(&format!("S      1G      1D{nd:>7}P{:>7}", pseq - 1), 'T', 1)
}

/// The general path's answer.
fn general<T>(
    file: &IgesFile<'_>,
    entry: &super::DirectoryEntry,
    f: impl FnOnce(&super::super::Parameters<'_>) -> Result<T, super::ParseError>,
) -> Decoded<T> {
    file.general(entry, f)
}

/// Decodes every entity both ways and compares; returns how many the direct reader read
/// itself (did not hand to the general path).
fn compare(text: &str) -> Result<usize, TestCaseError> {
    let Ok(file) = parse(text) else {
        return Ok(0);
    };
    let mut scratch = Scratch::default();
    let mut direct = 0;
    for entry in file.entries.iter().flatten() {
        match entry.entity_type {
            126 => {
                let fast = file.decode_curve126(entry, &mut scratch);
                let slow = general(&file, entry, Curve126::from_params);
                prop_assert_eq!(format!("{fast:?}"), format!("{slow:?}"));
                direct += usize::from(
                    file.direct(entry, &mut scratch, super::read_curve)
                        .is_some(),
                );
            }
            128 => {
                let fast = file.decode_surface128(entry, &mut scratch);
                let slow = general(&file, entry, Surface128::from_params);
                prop_assert_eq!(format!("{fast:?}"), format!("{slow:?}"));
                direct += usize::from(
                    file.direct(entry, &mut scratch, super::read_surface)
                        .is_some(),
                );
            }
            _ => {}
        }
    }
    Ok(direct)
}

/// A real parameter in one of many spellings, sometimes empty, blank-padded or invalid.
fn real_text() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => any::<f64>().prop_filter("finite", |x| x.is_finite()).prop_map(|x| format!("{x:?}")),
        2 => (-1e6f64..1e6).prop_map(|x| format!("{x:E}").replace('E', "D")),
        2 => (-1e3f64..1e3).prop_map(|x| format!("{x:e}")),
        2 => "[+-]?[0-9]{0,3}\\.[0-9]{0,25}",
        1 => "[+-]?[0-9]{1,5}",
        1 => "[0-9]{1,3}\\.[0-9]{1,3}[EeDd][+-]?[0-9]{1,3}",
        1 => Just(String::new()),
        1 => Just(" 1.5 ".to_owned()),
        1 => prop_oneof![Just("1.2.3"), Just("1.0D"), Just("x"), Just("2Hab"), Just("1e400"), Just("1.5 2"), Just(".")].prop_map(str::to_owned),
    ]
}

/// `n` reals, mostly valid (`bad` = allow the invalid spellings).
fn reals(n: usize, bad: bool) -> impl Strategy<Value = Vec<String>> {
    let good = prop_oneof![
        any::<f64>()
            .prop_filter("finite", |x| x.is_finite())
            .prop_map(|x| format!("{x:?}")),
        (-100.0f64..100.0).prop_map(|x| format!("{x}")),
        Just("1.".to_owned()),
        Just("0.".to_owned()),
    ];
    if bad {
        prop::collection::vec(real_text().boxed(), n)
    } else {
        prop::collection::vec(good.boxed(), n)
    }
}

fn join(parts: &[String], p: char, r: char) -> String {
    let mut s = parts.join(&p.to_string());
    s.push(r);
    s
}

/// A 126 record: `K`, `M`, flags, then the right number of values, with the tail
/// (`V(0)`, `V(1)`, normal, extras) cut anywhere.
fn curve() -> impl Strategy<Value = (Vec<String>, bool)> {
    (1usize..6, 1usize..4, any::<bool>(), 0usize..9).prop_flat_map(|(k, m, bad, tail)| {
        let m = m.min(k);
        let n = (k + m + 2) + (k + 1) + 3 * (k + 1);
        (reals(n, bad), reals(8, bad), Just((k, m, tail, bad))).prop_map(
            |(body, more, (k, m, tail, bad))| {
                let mut v = vec!["126".to_owned(), k.to_string(), m.to_string()];
                v.extend(["0", "0", "1", "0"].map(str::to_owned));
                v.extend(body);
                v.extend(more.into_iter().take(tail));
                (v, bad)
            },
        )
    })
}

/// A 128 record, built like [`curve`].
fn surface() -> impl Strategy<Value = (Vec<String>, bool)> {
    (
        1usize..5,
        1usize..5,
        1usize..3,
        1usize..3,
        any::<bool>(),
        0usize..7,
    )
        .prop_flat_map(|(k1, k2, m1, m2, bad, tail)| {
            let (m1, m2) = (m1.min(k1), m2.min(k2));
            let c = (k1 + 1) * (k2 + 1);
            let n = (k1 + m1 + 2) + (k2 + m2 + 2) + 4 * c;
            (
                reals(n, bad),
                reals(6, bad),
                Just((k1, k2, m1, m2, tail, bad)),
            )
                .prop_map(|(body, more, (k1, k2, m1, m2, tail, bad))| {
                    let mut v = vec!["128".to_owned()];
                    v.extend([k1, k2, m1, m2].map(|x| x.to_string()));
                    v.extend(["0", "0", "0", "0", "0"].map(str::to_owned));
                    v.extend(body);
                    v.extend(more.into_iter().take(tail));
                    (v, bad)
                })
        })
}

/// Damage to apply to a parameter list.
#[derive(Debug, Clone)]
enum Damage {
    None,
    /// Drop the parameters from this fraction (per mille) of the list on (and the record delimiter
    /// with them half the time).
    Truncate(usize, bool),
    /// Replace the parameter at this fraction (per mille) with a text.
    Replace(usize, String),
    /// Blanks around every parameter.
    Blanks,
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        4 => Just(Damage::None),
        1 => (0usize..1000, any::<bool>()).prop_map(|(f, d)| Damage::Truncate(f, d)),
        2 => (0usize..1000, prop_oneof![
            real_text(),
            Just("-1".to_owned()),
            Just("99999999999".to_owned()),
            Just("3Ha,b".to_owned()),
            Just("127".to_owned()),
            Just("1;2".to_owned()),
        ]).prop_map(|(f, t)| Damage::Replace(f, t)),
        1 => Just(Damage::Blanks),
    ]
}

fn apply(v: &mut Vec<String>, d: &Damage) -> bool {
    match d {
        Damage::None => true,
        Damage::Truncate(f, keep_end) => {
            // The type number stays: an entity with no parameter data at all has no P
            // lines, which breaks the file's structure (a file-level error that
            // tests/robustness.rs covers), not the entity's decoding tested here.
            v.truncate((*f * v.len() / 1000).max(1));
            *keep_end
        }
        Damage::Replace(f, t) => {
            let i = (*f * v.len() / 1000).min(v.len() - 1);
            v[i] = t.clone();
            true
        }
        Damage::Blanks => {
            for s in v.iter_mut() {
                *s = format!(" {s}  ");
            }
            true
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    /// Files of several curves and surfaces: both paths give the same records, warnings and
    /// errors; clean records (no damage, valid reals, whole tokens per line) are read by the
    /// direct reader itself.
    #[test]
    fn direct_equals_general(
        items in prop::collection::vec((any::<bool>(), curve(), surface(), damage(), 1usize..=64, -1i64..=1), 1..5),
        custom in any::<bool>(),
    ) {
        let (p, r) = if custom { ('/', '#') } else { (',', ';') };
        let mut ents = Vec::new();
        let mut clean = 0;
        for (is_curve, (cv, cbad), (sv, sbad), dmg, width, delta) in items {
            let (ty, mut v, bad) = if is_curve { (126, cv, cbad) } else { (128, sv, sbad) };
            if custom {
                // The default delimiters may occur in the damage texts: keep them literal.
                for s in &mut v {
                    *s = s.replace([',', ';'], "");
                }
            }
            let with_end = apply(&mut v, &dmg);
            let mut text = join(&v, p, r);
            if !with_end {
                text.pop();
            }
            // Whole tokens on each line: break after delimiters only.
            let width = if width >= 64 { 64 } else { width };
            if !bad && matches!(dmg, Damage::None) && width == 64 {
                clean += 1;
                // Pack parameters into lines of at most 64 columns, never splitting one.
                let mut packed = String::new();
                let mut line = String::new();
                for tok in text.split_inclusive([p, r]) {
                    if line.len() + tok.len() > 64 {
                        packed += &format!("{line:<64}");
                        line.clear();
                    }
                    line += tok;
                }
                packed += &line;
                text = packed;
            }
            ents.push((ty, text, width, delta));
        }
        let doc = document(custom.then_some((p, r)), &ents);
        if let Ok(file) = parse(&doc) {
            prop_assert_eq!(file.tokenizer().param, p as u8);
            prop_assert_eq!(file.entries.len(), ents.len());
        } else {
            prop_assert!(false, "test document does not parse: {doc}");
        }
        let direct = compare(&doc)?;
        prop_assert!(direct >= clean, "{direct} direct < {clean} clean\n{doc}");
    }
}

#[test]
fn hand_written_cases() {
    let surface = "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;";
    let curve = "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,1.,1.,0.,1.;";
    for (ty, text, direct) in [
        (126, curve.to_owned(), 1),
        (128, surface.to_owned(), 1),
        // The record ends before V(1): the general path reads V(1) as absent.
        (126, curve.replace(",0.,1.;", ",0.;"), 1),
        // Blanks around values and an empty knot (= 0.0).
        (126, curve.replace("0.,0.,1.", " 0. ,, 1."), 1),
        // D exponents and a leading point.
        (
            128,
            surface.replace("1.,1.,0.,0.,1.", "1.D0,.1D1,0.,0.,1.E0"),
            1,
        ),
        // A comment after the record delimiter.
        (126, format!("{curve} comment, 1.5;"), 1),
        // Errors: a bad real, a wrong type, a Hollerith, a missing value.
        (126, curve.replace("0.,0.,1.", "0.,0.,1.x"), 0),
        (126, curve.replacen("126", "128", 1), 0),
        (
            128,
            surface.replace("0.,0.,1.,1.,0.", "0.,0.,1.,1.,2Hab"),
            0,
        ),
        (126, curve.replace(",1.,1.,0.,1.;", ";"), 0),
    ] {
        let doc = document(None, &[(ty, text.clone(), 64, 0)]);
        let direct_count = compare(&doc).unwrap();
        assert_eq!(direct_count, direct, "{text}");
    }
}
