//! The Directory Entry (IGES 5.3 section 2.2.4.4): two records of ten
//! 8-column fields each, the twentieth and tenth being the section letter and sequence
//! number.
//!
//! ```text
//! directory-entry = first-record second-record
//! first-record    = type pointer structure font level view transform label-display status
//! second-record   = type weight color line-count form reserved reserved label subscript
//! ```

use nom::Parser;

use super::super::directory::{DirectoryEntry, Status};
use super::super::error::{ErrorKind, ParseError};
use super::parameters::{Rule, integer};
use super::records::Record;

const NAMES1: [&str; 9] = [
    "entity type",
    "parameter data pointer",
    "structure",
    "line font pattern",
    "level",
    "view",
    "transformation matrix",
    "label display associativity",
    "status number",
];
const NAMES2: [&str; 9] = [
    "entity type",
    "line weight",
    "color",
    "parameter line count",
    "form number",
    "reserved",
    "reserved",
    "entity label",
    "entity subscript",
];

/// An 8-column field: up to eight bytes (a short record ends early).
fn column_field(i: &[u8]) -> Rule<'_, &[u8]> {
    let n = i.len().min(8);
    Ok((&i[n..], &i[..n]))
}

/// The nine 8-column fields of columns 1-72 of one record.
fn fields(data: &[u8]) -> [&[u8]; 9] {
    let mut p = (
        column_field,
        column_field,
        column_field,
        column_field,
        column_field,
        column_field,
        column_field,
        column_field,
        column_field,
    );
    match p.parse(data) {
        Ok((_, (a, b, c, d, e, f, g, h, k))) => [a, b, c, d, e, f, g, h, k],
        Err(_) => [&[][..]; 9],
    }
}

/// `integer-field`: a right-justified integer; a blank field is 0.
fn integer_field(f: &[u8]) -> Option<i64> {
    let t = f.trim_ascii();
    if t.is_empty() { Some(0) } else { integer(t) }
}

/// `status`: four 2-digit numbers, right-justified; blanks count as 0 (some writers
/// leave them).
fn status(f: &[u8]) -> Option<Status> {
    let t = f.trim_ascii_end();
    let pad = 8usize.checked_sub(t.len())?;
    let mut d = [0u8; 8];
    for (k, &c) in t.iter().enumerate() {
        d[pad + k] = match c {
            b' ' => 0,
            b'0'..=b'9' => c - b'0',
            _ => return None,
        };
    }
    Some(Status {
        blank: d[0] * 10 + d[1],
        subordinate: d[2] * 10 + d[3],
        use_flag: d[4] * 10 + d[5],
        hierarchy: d[6] * 10 + d[7],
    })
}

/// `directory-entry`: the two records of the entry whose first record is D sequence
/// `pointer`; a field that is not what it must be is a located error naming the field.
pub fn directory_entry(
    r1: &Record<'_>,
    r2: &Record<'_>,
    pointer: usize,
) -> Result<DirectoryEntry, ParseError> {
    let f1 = fields(r1.data.as_bytes());
    let f2 = fields(r2.data.as_bytes());
    let bad = |r: &Record<'_>, k: usize, field: u8, name: &'static str, text: &[u8]| {
        ParseError::new(
            ErrorKind::BadField {
                field,
                name,
                text: String::from_utf8_lossy(text).into_owned(),
            },
            'D',
            r.sequence,
        )
        .at_column(k * 8 + 1)
        .at_line(r.line)
        .of_entity(pointer)
    };
    // k < 9: the fields of one record.
    #[allow(clippy::cast_possible_truncation)]
    let int1 =
        |k: usize| integer_field(f1[k]).ok_or_else(|| bad(r1, k, 1 + k as u8, NAMES1[k], f1[k]));
    #[allow(clippy::cast_possible_truncation)]
    let int2 =
        |k: usize| integer_field(f2[k]).ok_or_else(|| bad(r2, k, 11 + k as u8, NAMES2[k], f2[k]));
    let entity_type = int1(0)?;
    let second = int2(0)?;
    if entity_type != second {
        return Err(ParseError::new(
            ErrorKind::TypeMismatch {
                first: entity_type,
                second,
            },
            'D',
            r2.sequence,
        )
        .at_column(1)
        .at_line(r2.line)
        .of_entity(pointer));
    }
    let status = status(f1[8]).ok_or_else(|| bad(r1, 8, 9, NAMES1[8], f1[8]))?;
    let text = |f: &[u8]| String::from_utf8_lossy(f.trim_ascii()).into_owned();
    Ok(DirectoryEntry {
        pointer,
        line: r1.line,
        entity_type,
        parameter_pointer: int1(1)?,
        structure: int1(2)?,
        line_font: int1(3)?,
        level: int1(4)?,
        view: int1(5)?,
        transform: int1(6)?,
        label_display: int1(7)?,
        status,
        line_weight: int2(1)?,
        color: int2(2)?,
        parameter_line_count: int2(3)?,
        form: int2(4)?,
        reserved: [text(f2[5]), text(f2[6])],
        label: text(f2[7]),
        subscript: int2(8)?,
    })
}
