//! Directory Entries: two 80-column records of ten 8-column fields each (IGES 5.3 section
//! 2.2.4.4; spec.md a.4).

use super::error::{ErrorKind, ParseError};
use super::params::parse_int;
use super::records::{Record, field};

/// The status number (DE field 9): four 2-digit fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Status {
    /// Digits 1-2: 0 visible, 1 blanked.
    pub blank: u8,
    /// Digits 3-4: 0 independent, 1 physically dependent, 2 logically, 3 both.
    pub subordinate: u8,
    /// Digits 5-6: 0 geometry, 1 annotation, 2 definition, 3 other, 4 logical/positional,
    /// 5 2-D parametric, 6 construction.
    pub use_flag: u8,
    /// Digits 7-8: 0 global top-down, 1 global defer, 2 use hierarchy property.
    pub hierarchy: u8,
}

impl Status {
    /// Parses the 8-column field; blanks count as 0 (some writers leave them).
    pub fn parse(text: &str) -> Option<Status> {
        let t = text.as_bytes();
        // Right-justified: pad on the left to 8 columns.
        if t.len() > 8 {
            return None;
        }
        let mut d = [0u8; 8];
        let pad = 8 - t.len();
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

    /// The 8-digit form written in DE field 9.
    pub fn to_digits(self) -> String {
        format!(
            "{:02}{:02}{:02}{:02}",
            self.blank % 100,
            self.subordinate % 100,
            self.use_flag % 100,
            self.hierarchy % 100
        )
    }
}

/// One Directory Entry, all twenty fields (the two sequence fields as `pointer`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DirectoryEntry {
    /// The DE pointer: the sequence number of the first record (odd; `2 i + 1` for the
    /// `i`-th entry, counted by position).
    pub pointer: usize,
    /// 1-based file line of the first record.
    pub line: usize,
    /// Field 1 (and 11): entity type number.
    pub entity_type: i64,
    /// Field 2: parameter data pointer (P sequence number of the first line).
    pub parameter_pointer: i64,
    /// Field 3: structure (0 or negated DE pointer).
    pub structure: i64,
    /// Field 4: line font pattern.
    pub line_font: i64,
    /// Field 5: level.
    pub level: i64,
    /// Field 6: view.
    pub view: i64,
    /// Field 7: transformation matrix (0 or DE pointer of a 124).
    pub transform: i64,
    /// Field 8: label display associativity.
    pub label_display: i64,
    /// Field 9: status number.
    pub status: Status,
    /// Field 12: line weight number.
    pub line_weight: i64,
    /// Field 13: color number.
    pub color: i64,
    /// Field 14: parameter line count.
    pub parameter_line_count: i64,
    /// Field 15: form number.
    pub form: i64,
    /// Fields 16-17: reserved (kept as text).
    pub reserved: [String; 2],
    /// Field 18: entity label (up to 8 characters, trimmed).
    pub label: String,
    /// Field 19: entity subscript number.
    pub subscript: i64,
}

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

impl DirectoryEntry {
    /// Parses the two records of the entry whose first record is D sequence `pointer`.
    pub fn parse(r1: &Record<'_>, r2: &Record<'_>, pointer: usize) -> Result<Self, ParseError> {
        let int = |r: &Record<'_>, k: usize, names: &[&'static str; 9], base: u8| {
            let text = field(r.data, k * 8, k * 8 + 8);
            let t = text.trim();
            if t.is_empty() {
                return Ok(0);
            }
            parse_int(t).ok_or_else(|| {
                ParseError::new(
                    ErrorKind::BadField {
                        // k < 9: the fields of one 80-column record.
                        #[allow(clippy::cast_possible_truncation)]
                        field: base + k as u8,
                        name: names[k],
                        text: text.to_owned(),
                    },
                    'D',
                    r.sequence,
                )
                .at_column(k * 8 + 1)
                .at_line(r.line)
                .of_entity(pointer)
            })
        };
        let entity_type = int(r1, 0, &NAMES1, 1)?;
        let second = int(r2, 0, &NAMES2, 11)?;
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
        let status_text = field(r1.data, 64, 72);
        let status = Status::parse(status_text.trim_end()).ok_or_else(|| {
            ParseError::new(
                ErrorKind::BadField {
                    field: 9,
                    name: NAMES1[8],
                    text: status_text.to_owned(),
                },
                'D',
                r1.sequence,
            )
            .at_column(65)
            .at_line(r1.line)
            .of_entity(pointer)
        })?;
        Ok(DirectoryEntry {
            pointer,
            line: r1.line,
            entity_type,
            parameter_pointer: int(r1, 1, &NAMES1, 1)?,
            structure: int(r1, 2, &NAMES1, 1)?,
            line_font: int(r1, 3, &NAMES1, 1)?,
            level: int(r1, 4, &NAMES1, 1)?,
            view: int(r1, 5, &NAMES1, 1)?,
            transform: int(r1, 6, &NAMES1, 1)?,
            label_display: int(r1, 7, &NAMES1, 1)?,
            status,
            line_weight: int(r2, 1, &NAMES2, 11)?,
            color: int(r2, 2, &NAMES2, 11)?,
            parameter_line_count: int(r2, 3, &NAMES2, 11)?,
            form: int(r2, 4, &NAMES2, 11)?,
            reserved: [
                field(r2.data, 40, 48).trim().to_owned(),
                field(r2.data, 48, 56).trim().to_owned(),
            ],
            label: field(r2.data, 56, 64).trim().to_owned(),
            subscript: int(r2, 8, &NAMES2, 11)?,
        })
    }
}
