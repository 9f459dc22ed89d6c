//! The Global section: delimiters and the 26 typed parameters (IGES 5.3 section 2.2.4.3;
//! spec.md a.2).

use super::error::{ErrorKind, ParseError, ParseWarning};
use super::params::{Token, TokenKind, Tokenizer, parse_int};
use super::records::Record;
use crate::real::parse_iges_real;

/// The Global section, every parameter typed. Empty (defaulted) parameters are `None`,
/// except the delimiters, which always hold the effective value.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Global {
    /// 1: parameter delimiter (default `,`).
    pub param_delimiter: char,
    /// 2: record delimiter (default `;`).
    pub record_delimiter: char,
    /// 3: product identification from the sending system.
    pub product_id_sender: Option<String>,
    /// 4: file name.
    pub file_name: Option<String>,
    /// 5: native system id.
    pub native_system_id: Option<String>,
    /// 6: preprocessor version.
    pub preprocessor_version: Option<String>,
    /// 7: number of binary bits for integer representation.
    pub integer_bits: Option<i64>,
    /// 8: maximum power of ten representable in single precision.
    pub single_max_power: Option<i64>,
    /// 9: significant digits in single precision.
    pub single_digits: Option<i64>,
    /// 10: maximum power of ten representable in double precision.
    pub double_max_power: Option<i64>,
    /// 11: significant digits in double precision.
    pub double_digits: Option<i64>,
    /// 12: product identification for the receiving system.
    pub product_id_receiver: Option<String>,
    /// 13: model space scale (model : real world; default 1).
    pub model_scale: Option<f64>,
    /// 14: units flag (1 inch, 2 mm, 3 named in 15, 4 ft, 5 mi, 6 m, 7 km, 8 mil, 9 um,
    /// 10 cm, 11 microinch).
    pub units_flag: Option<i64>,
    /// 15: units name.
    pub units_name: Option<String>,
    /// 16: maximum number of line weight gradations.
    pub line_weight_gradations: Option<i64>,
    /// 17: width of the maximum line weight in units.
    pub max_line_width: Option<f64>,
    /// 18: date and time of file generation (`YYMMDD.HHNNSS` or `YYYYMMDD.HHNNSS`).
    pub date: Option<String>,
    /// 19: minimum user-intended resolution in units.
    pub resolution: Option<f64>,
    /// 20: approximate maximum coordinate value in units.
    pub max_coordinate: Option<f64>,
    /// 21: author.
    pub author: Option<String>,
    /// 22: author's organization.
    pub organization: Option<String>,
    /// 23: IGES version flag (11 = 5.3).
    pub version_flag: Option<i64>,
    /// 24: drafting standard flag.
    pub drafting_standard: Option<i64>,
    /// 25: date and time the model was created or last modified.
    pub modified_date: Option<String>,
    /// 26: application protocol / subset identifier.
    pub application_protocol: Option<String>,
}

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

impl Global {
    /// The version flag as a name (`IGES 5.3` for 11), when known.
    pub fn version_name(&self) -> Option<&'static str> {
        Some(match self.version_flag? {
            1 => "IGES 1.0",
            2 => "ANSI Y14.26M-1981",
            3 => "IGES 2.0",
            4 => "IGES 3.0",
            5 => "ASME/ANSI Y14.26M-1987",
            6 => "IGES 4.0",
            7 => "ASME Y14.26M-1989",
            8 => "IGES 5.0",
            9 => "IGES 5.1",
            10 => "IGES 5.2",
            11 => "IGES 5.3",
            _ => return None,
        })
    }

    /// The tokenizer built from this section's delimiters.
    pub fn tokenizer(&self) -> Tokenizer {
        Tokenizer {
            param: self.param_delimiter as u8,
            record: self.record_delimiter as u8,
        }
    }

    /// Parses the Global section from its records (data columns 1-72 of each).
    ///
    /// Delimiter bootstrap (spec.md a.2): a first character equal to `,` means the default
    /// parameter delimiter; otherwise parameter 1 must be `1Hx`. Parameter 2 is then empty
    /// (default `;`) or `1Hy`. Malformed ordinary parameters become `None` with a
    /// `global_field` warning; a malformed units flag (14) or model scale (13) is an error,
    /// because coordinates depend on them.
    pub fn parse(
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
            let mut e = ParseError::new(kind, 'G', rec.map_or(0, |r| r.sequence))
                .at_column(offset % 72 + 1);
            if let Some(r) = rec {
                e = e.at_line(r.line);
            }
            e
        };
        let b = data.as_bytes();
        let mut i = 0;
        while i < b.len() && b[i] == b' ' {
            i += 1;
        }
        // Parameter 1.
        let (param, after1) = if b.get(i) == Some(&b',') {
            (b',', i)
        } else {
            let (c, next) = hollerith_char(b, i).ok_or_else(|| {
                locate(
                    i,
                    ErrorKind::BadDelimiter(
                        "parameter 1 must be empty or a 1H Hollerith character".into(),
                    ),
                )
            })?;
            (c, next)
        };
        let mut i = after1;
        while i < b.len() && b[i] == b' ' {
            i += 1;
        }
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
        while i < b.len() && b[i] == b' ' {
            i += 1;
        }
        // Parameter 2.
        let (record, after2, had_record_end) = match b.get(i) {
            Some(&c) if c == param || (c == b',' && param != b',') => (b';', i + 1, false),
            Some(b';') if param != b';' => (b';', i, true),
            _ => {
                let (c, mut next) = hollerith_char(b, i).ok_or_else(|| {
                    locate(
                        i,
                        ErrorKind::BadDelimiter(
                            "parameter 2 must be empty or a 1H Hollerith character".into(),
                        ),
                    )
                })?;
                while next < b.len() && b[next] == b' ' {
                    next += 1;
                }
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
        let tok = Tokenizer { param, record };
        let mut tokens: Vec<Token> = Vec::with_capacity(24);
        tok.tokenize(&data, after2, &mut tokens, 4096)
            .map_err(|e| locate(e.offset, e.kind))?;
        for (k, t) in tokens.iter().enumerate() {
            let index = k + 3;
            let Some(&(ty, name)) = TYPES.get(index - 1) else {
                warnings.push(gwarn(
                    "global_field",
                    &format!("{} extra Global parameters ignored", tokens.len() + 2 - 26),
                    records,
                ));
                break;
            };
            let text = t.text(&data);
            let val = match (t.kind, ty) {
                (TokenKind::Empty, _) => Val::None,
                (TokenKind::Hollerith, Ty::Str) => Val::Str(text.to_owned()),
                (TokenKind::Plain, Ty::Int) => match parse_int(text) {
                    Some(v) => Val::Int(v),
                    None => {
                        // Some writers put a real where an integer is expected (`2.`).
                        match parse_iges_real(text) {
                            // A whole number below 1e15 converts to i64 exactly.
                            #[allow(clippy::cast_possible_truncation)]
                            Ok(r) if r.fract() == 0.0 && r.abs() < 1e15 => Val::Int(r as i64),
                            _ => bad(
                                index,
                                name,
                                "an integer",
                                text,
                                t,
                                &locate,
                                warnings,
                                records,
                            )?,
                        }
                    }
                },
                (TokenKind::Plain, Ty::Real) => match parse_iges_real(text) {
                    Ok(r) => Val::Real(r),
                    Err(_) => bad(index, name, "a real", text, t, &locate, warnings, records)?,
                },
                _ => bad(
                    index,
                    name,
                    match ty {
                        Ty::Str => "a Hollerith string",
                        Ty::Int => "an integer",
                        Ty::Real => "a real",
                    },
                    text,
                    t,
                    &locate,
                    warnings,
                    records,
                )?,
            };
            g.set(index, val);
        }
        Ok(g)
    }

    fn set(&mut self, index: usize, v: Val) {
        let s = |v: Val| match v {
            Val::Str(s) => Some(s),
            _ => None,
        };
        match index {
            3 => self.product_id_sender = s(v),
            4 => self.file_name = s(v),
            5 => self.native_system_id = s(v),
            6 => self.preprocessor_version = s(v),
            12 => self.product_id_receiver = s(v),
            15 => self.units_name = s(v),
            18 => self.date = s(v),
            21 => self.author = s(v),
            22 => self.organization = s(v),
            25 => self.modified_date = s(v),
            26 => self.application_protocol = s(v),
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
                    7 => self.integer_bits = int,
                    8 => self.single_max_power = int,
                    9 => self.single_digits = int,
                    10 => self.double_max_power = int,
                    11 => self.double_digits = int,
                    13 => self.model_scale = real,
                    14 => self.units_flag = int,
                    16 => self.line_weight_gradations = int,
                    17 => self.max_line_width = real,
                    19 => self.resolution = real,
                    20 => self.max_coordinate = real,
                    23 => self.version_flag = int,
                    24 => self.drafting_standard = int,
                    _ => {}
                }
            }
        }
    }
}

/// A malformed Global parameter: an error for the unit flag and model scale, else a warning.
#[allow(clippy::too_many_arguments)]
fn bad(
    index: usize,
    name: &'static str,
    expected: &'static str,
    text: &str,
    t: &Token,
    locate: &dyn Fn(usize, ErrorKind) -> ParseError,
    warnings: &mut Vec<ParseWarning>,
    records: &[Record<'_>],
) -> Result<Val, ParseError> {
    let kind = ErrorKind::BadParameter {
        index,
        name,
        expected,
        found: text.to_owned(),
    };
    if index == 13 || index == 14 {
        return Err(locate(t.start as usize, kind));
    }
    let e = locate(t.start as usize, kind);
    warnings.push(ParseWarning {
        code: "global_field",
        message: format!("{} (ignored)", e.kind),
        section: 'G',
        sequence: e.sequence,
        de: None,
        line: e.line,
    });
    let _ = records;
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

/// Reads `1Hx` at `i`: the character and the offset after it.
fn hollerith_char(b: &[u8], i: usize) -> Option<(u8, usize)> {
    if b.get(i) == Some(&b'1') && matches!(b.get(i + 1), Some(b'H' | b'h')) {
        let c = *b.get(i + 2)?;
        Some((c, i + 3))
    } else {
        None
    }
}
