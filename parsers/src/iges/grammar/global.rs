//! The Global section (IGES 5.3 section 2.2.4.3): the two delimiters, then
//! 24 typed parameters in the free format of section 2.2.3.
//!
//! ```text
//! global    = delimiter-1 separator delimiter-2 separator { parameter } record-delimiter
//! delimiter = default | "1H" character
//! ```
//!
//! The first two parameters define the delimiters the rest is read with, so they are read
//! by a bootstrap rule of their own (`delimiter_definition`); everything after them by
//! [`ParameterReader`].

use super::super::error::{ErrorKind, ParseError, ParseWarning};
use super::super::global::Global;
use super::parameters::{Delimiters, Parameter, ParameterReader, blanks, hollerith, integer};
use super::records::Record;
use crate::real::parse_iges_real;

/// The type of each Global parameter, by index 1..=26.
#[derive(Clone, Copy)]
enum Ty {
    Str,
    Int,
    Real,
}

const TYPES: [(Ty, &str); 26] = [
    (Ty::Str, "parameter delimiter"),
    (Ty::Str, "record delimiter"),
    (Ty::Str, "product id (sender)"),
    (Ty::Str, "file name"),
    (Ty::Str, "native system id"),
    (Ty::Str, "preprocessor version"),
    (Ty::Int, "integer bits"),
    (Ty::Int, "single precision max power"),
    (Ty::Int, "single precision digits"),
    (Ty::Int, "double precision max power"),
    (Ty::Int, "double precision digits"),
    (Ty::Str, "product id (receiver)"),
    (Ty::Real, "model space scale"),
    (Ty::Int, "units flag"),
    (Ty::Str, "units name"),
    (Ty::Int, "line weight gradations"),
    (Ty::Real, "max line width"),
    (Ty::Str, "file date"),
    (Ty::Real, "resolution"),
    (Ty::Real, "max coordinate"),
    (Ty::Str, "author"),
    (Ty::Str, "organization"),
    (Ty::Int, "version flag"),
    (Ty::Int, "drafting standard"),
    (Ty::Str, "model date"),
    (Ty::Str, "application protocol"),
];

/// A typed Global value.
enum Val {
    None,
    Str(String),
    Int(i64),
    Real(f64),
}

/// `"1H" character` at the start of `i` (after blanks): the delimiter a Global parameter
/// 1 or 2 declares, and the input after it.
fn delimiter_definition(i: &[u8]) -> Option<(&[u8], u8)> {
    let (i, _) = blanks(i).ok()?;
    match hollerith(i) {
        Ok((rest, s)) if s.len() == 1 && i.first() == Some(&b'1') => Some((rest, s.as_bytes()[0])),
        _ => None,
    }
}

/// Parses the Global section from its records (data columns 1-72 of each).
///
/// Delimiter bootstrap (section 2.2.4.3): a first character equal to `,` means the default
/// parameter delimiter; otherwise parameter 1 must be `1Hx`. Parameter 2 is then empty
/// (default `;`) or `1Hy`. Malformed ordinary parameters become `None` with a
/// `global_field` warning; a malformed units flag (14) or model scale (13) is an error,
/// because coordinates depend on them.
pub fn global_section(
    records: &[Record<'_>],
    warnings: &mut Vec<ParseWarning>,
) -> Result<Global, ParseError> {
    let mut data = String::with_capacity(records.len() * 72);
    for r in records {
        data.push_str(r.data);
        for _ in r.data.len()..72 {
            data.push(' ');
        }
    }
    let locate = |offset: usize, kind: ErrorKind| -> ParseError {
        let idx = offset / 72;
        let rec = records.get(idx).or(records.last());
        let mut e =
            ParseError::new(kind, 'G', rec.map_or(0, |r| r.sequence)).at_column(offset % 72 + 1);
        if let Some(r) = rec {
            e = e.at_line(r.line);
        }
        e
    };
    let b = data.as_bytes();
    let at = |rest: &[u8]| b.len() - rest.len();
    let skip = |i: usize| {
        i + b[i.min(b.len())..]
            .iter()
            .take_while(|&&c| c == b' ')
            .count()
    };
    let i = skip(0);
    // Parameter 1.
    let (param, after1) = if b.get(i) == Some(&b',') {
        (b',', i)
    } else {
        let (rest, c) = delimiter_definition(&b[i..]).ok_or_else(|| {
            locate(
                i,
                ErrorKind::BadDelimiter(
                    "parameter 1 must be empty or a 1H Hollerith character".into(),
                ),
            )
        })?;
        (c, at(rest))
    };
    let mut i = skip(after1);
    // The separator after parameter 1 is the new parameter delimiter; some writers put
    // a comma there even when declaring another delimiter (tolerated with a warning).
    match b.get(i) {
        Some(&c) if c == param => i += 1,
        Some(b',') => {
            warnings.push(gwarn(
                "delimiter_form",
                "a comma follows parameter 1 although it declares another delimiter",
                records,
            ));
            i += 1;
        }
        _ => {
            return Err(locate(
                i,
                ErrorKind::BadDelimiter("parameter 1 is not followed by a delimiter".into()),
            ));
        }
    }
    let i = skip(i);
    // Parameter 2.
    let (record, after2, had_record_end) = match b.get(i) {
        Some(&c) if c == param || (c == b',' && param != b',') => (b';', i + 1, false),
        Some(b';') if param != b';' => (b';', i, true),
        _ => {
            let (rest, c) = delimiter_definition(&b[i..]).ok_or_else(|| {
                locate(
                    i,
                    ErrorKind::BadDelimiter(
                        "parameter 2 must be empty or a 1H Hollerith character".into(),
                    ),
                )
            })?;
            let next = skip(at(rest));
            match b.get(next) {
                Some(&d) if d == param => (c, next + 1, false),
                Some(&d) if d == c => (c, next, true),
                Some(b',') => {
                    warnings.push(gwarn(
                        "delimiter_form",
                        "a comma follows parameter 2 although it is not the parameter delimiter",
                        records,
                    ));
                    (c, next + 1, false)
                }
                _ => {
                    return Err(locate(
                        next,
                        ErrorKind::BadDelimiter(
                            "parameter 2 is not followed by a delimiter".into(),
                        ),
                    ));
                }
            }
        }
    };
    if param == record || !param.is_ascii_graphic() || !record.is_ascii_graphic() {
        return Err(locate(
            0,
            ErrorKind::BadDelimiter(format!(
                "delimiters {:?} and {:?} must be two different printable characters",
                param as char, record as char
            )),
        ));
    }
    let mut g = Global {
        param_delimiter: param as char,
        record_delimiter: record as char,
        ..Global::default()
    };
    if had_record_end {
        return Ok(g);
    }
    let mut reader = ParameterReader::new(&b[after2..], Delimiters { param, record }, 4096);
    let mut index = 3;
    loop {
        let before = reader.rest();
        let next = reader.parameter().map_err(|e| {
            // A Hollerith count that does not end its string at a delimiter is wrong: the
            // error is the count (IGES 5.3 section 2.2.2.4: nH then exactly n characters),
            // on its own line, not where the miscounted string happens to end.
            let from = b.len() - before.len();
            let from = from + before.iter().take_while(|&&c| c == b' ').count();
            let digits = b[from..].iter().take_while(|c| c.is_ascii_digit()).count();
            if digits > 0 && b.get(from + digits) == Some(&b'H') {
                let count = String::from_utf8_lossy(&b[from..from + digits]).into_owned();
                locate(
                    from,
                    ErrorKind::OutOfRange(format!(
                        "Global parameter {index}: the Hollerith count {count}H does not end the string at a delimiter ({})",
                        grammar_kind(e.cause)
                    )),
                )
            } else {
                locate(e.offset(b), grammar_kind(e.cause))
            }
        })?;
        let Some((start, p)) = next else {
            break;
        };
        let Some(&(ty, name)) = TYPES.get(index - 1) else {
            let extra = 1 + reader
                .skip_rest()
                .map_err(|e| locate(e.offset(b), grammar_kind(e.cause)))?;
            warnings.push(gwarn(
                "global_field",
                &format!("{extra} extra Global parameters ignored"),
                records,
            ));
            break;
        };
        let offset = at(start) + start.iter().take_while(|&&c| c == b' ').count();
        let mut bad = |expected: &'static str| {
            bad(
                index,
                name,
                expected,
                &p,
                locate(offset, ErrorKind::Unterminated(' ')),
                warnings,
            )
        };
        let val = match (p, ty) {
            (Parameter::Default, _) => Val::None,
            (Parameter::String(s), Ty::Str) => Val::Str(s.to_owned()),
            (Parameter::Value(v), Ty::Int) => match integer(v) {
                Some(v) => Val::Int(v),
                // Some writers put a real where an integer is expected (`2.`).
                None => match std::str::from_utf8(v).map(parse_iges_real) {
                    // A whole number below 1e15 converts to i64 exactly.
                    #[allow(clippy::cast_possible_truncation)]
                    Ok(Ok(r)) if r.fract() == 0.0 && r.abs() < 1e15 => Val::Int(r as i64),
                    _ => bad("an integer")?,
                },
            },
            (Parameter::Value(v), Ty::Real) => match std::str::from_utf8(v).map(parse_iges_real) {
                Ok(Ok(r)) => Val::Real(r),
                _ => bad("a real")?,
            },
            (_, Ty::Str) => bad("a Hollerith string")?,
            (_, Ty::Int) => bad("an integer")?,
            (_, Ty::Real) => bad("a real")?,
        };
        set(&mut g, index, val);
        index += 1;
    }
    Ok(g)
}

/// The IGES error kind of a grammar failure.
fn grammar_kind(cause: crate::grammar::Cause<ErrorKind>) -> ErrorKind {
    match cause {
        crate::grammar::Cause::Format(k) => k,
        crate::grammar::Cause::Syntax(k) => ErrorKind::Garbage(format!("{k:?}")),
    }
}

/// A malformed Global parameter: an error for the unit flag and model scale, else a
/// warning. `located` carries the location (its kind is replaced).
fn bad(
    index: usize,
    name: &'static str,
    expected: &'static str,
    p: &Parameter<'_>,
    located: ParseError,
    warnings: &mut Vec<ParseWarning>,
) -> Result<Val, ParseError> {
    let found = match p {
        Parameter::Default => String::new(),
        Parameter::String(s) => (*s).to_owned(),
        Parameter::Value(v) => String::from_utf8_lossy(v).into_owned(),
    };
    let e = ParseError {
        kind: ErrorKind::BadParameter {
            index,
            name,
            expected,
            found,
        },
        ..located
    };
    if index == 13 || index == 14 {
        return Err(e);
    }
    warnings.push(ParseWarning {
        code: "global_field",
        message: format!("{} (ignored)", e.kind),
        section: 'G',
        sequence: e.sequence,
        de: None,
        line: e.line,
    });
    Ok(Val::None)
}

fn gwarn(code: &'static str, message: &str, records: &[Record<'_>]) -> ParseWarning {
    ParseWarning {
        code,
        message: message.to_owned(),
        section: 'G',
        sequence: records.first().map_or(1, |r| r.sequence),
        de: None,
        line: records.first().map(|r| r.line),
    }
}

/// Stores Global parameter `index`.
fn set(g: &mut Global, index: usize, v: Val) {
    let s = |v: Val| match v {
        Val::Str(s) => Some(s),
        _ => None,
    };
    match index {
        3 => g.product_id_sender = s(v),
        4 => g.file_name = s(v),
        5 => g.native_system_id = s(v),
        6 => g.preprocessor_version = s(v),
        12 => g.product_id_receiver = s(v),
        15 => g.units_name = s(v),
        18 => g.date = s(v),
        21 => g.author = s(v),
        22 => g.organization = s(v),
        25 => g.modified_date = s(v),
        26 => g.application_protocol = s(v),
        _ => {
            let int = match v {
                Val::Int(i) => Some(i),
                _ => None,
            };
            let real = match v {
                Val::Real(r) => Some(r),
                Val::Int(i) => Some(i as f64),
                _ => None,
            };
            match index {
                7 => g.integer_bits = int,
                8 => g.single_max_power = int,
                9 => g.single_digits = int,
                10 => g.double_max_power = int,
                11 => g.double_digits = int,
                13 => g.model_scale = real,
                14 => g.units_flag = int,
                16 => g.line_weight_gradations = int,
                17 => g.max_line_width = real,
                19 => g.resolution = real,
                20 => g.max_coordinate = real,
                23 => g.version_flag = int,
                24 => g.drafting_standard = int,
                _ => {}
            }
        }
    }
}
