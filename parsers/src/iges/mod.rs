//! # IGES 5.3 fixed-column ASCII files
//!
//! The format layer for IGES: records and sections ([`records`]), the Global section with
//! its delimiters ([`global`]), Directory Entries ([`directory`]), the free-format
//! parameter tokenizer ([`params`]), typed records for entities 124, 126 and 128
//! ([`schema`], with all parameter-slot arithmetic in [`schema::layout`]) and the writer
//! ([`writer`]). No geometry: turning records into NURBS is left to the consumer of these records.
//!
//! ```
//! # use nurbsx_parsers::iges;
//! # fn rec(data: &str, s: char, n: usize) -> String { format!("{data:<72}{s}{n:>7}\n") }
//! let mut text = rec("a test file", 'S', 1);
//! text += &rec(",,;", 'G', 1);
//! text += &rec("     126       1       0       0       0       0       0       000000000", 'D', 1);
//! text += &rec("     126       0       0       1       0", 'D', 2);
//! text += &format!("{:<64} {:>7}P{:>7}\n", "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,1.,1.,0.,1.;", 1, 1);
//! text += &rec("S      1G      1D      2P      1", 'T', 1);
//! let file = iges::parse(&text)?;
//! let entry = file.entries[0].as_ref().unwrap();
//! let curve = iges::schema::Curve126::from_params(&file.parameters(entry)?)?;
//! assert_eq!(curve.points[1], [1., 1., 1.]);
//! assert_eq!((curve.v0, curve.v1), (Some(0.), Some(1.)));
//! assert_eq!(curve.normal, None); // the optional normal is absent
//! # Ok::<(), iges::ParseError>(())
//! ```
//!
//! Robustness: every count read from the file is compared with the parameters actually
//! present before anything is allocated; all conversions are checked; one entity's bad
//! parameters give a located error for that entity only ([`IgesFile::parameters`] is
//! called per entity), the others still parse.

pub mod direct;
pub mod directory;
pub mod error;
pub mod global;
pub mod params;
pub mod records;
pub mod schema;
pub mod writer;

pub use direct::{Decoded, Scratch};
pub use directory::{DirectoryEntry, Status};
pub use error::{ErrorKind, ParseError, ParseWarning, WriteError};
pub use global::Global;
pub use params::{Token, TokenKind, Tokenizer};
pub use records::Record;

use crate::Limits;
use crate::real::parse_iges_real;
use records::field;

/// Data columns of a Parameter Data record (1-64); 65 is blank, 66-72 the back-pointer.
pub const P_DATA_COLUMNS: usize = 64;

/// A parsed IGES file: the Start text, the Global section, the Directory Entries, and
/// the Parameter Data records, which are tokenized per entity on demand.
#[derive(Debug, Clone)]
pub struct IgesFile<'a> {
    /// The Start section text (columns 1-72 of each S record, right-trimmed, joined by `\n`).
    pub start: String,
    /// The Global section.
    pub global: Global,
    /// One result per Directory Entry, in file order: a bad entry is a located error and
    /// does not stop the others.
    pub entries: Vec<Result<DirectoryEntry, ParseError>>,
    /// What the parser tolerated (CRLF, short lines, sequence numbers, counts).
    pub warnings: Vec<ParseWarning>,
    /// Terminate record counts `[S, G, D, P]` as declared, when readable.
    pub terminate_counts: Option<[usize; 4]>,
    parameters: Vec<Record<'a>>,
    tokenizer: Tokenizer,
    limits: Limits,
}

/// Parses an IGES file with the default [`Limits`].
pub fn parse(text: &str) -> Result<IgesFile<'_>, ParseError> {
    parse_with(text, &Limits::default())
}

/// Parses an IGES file: sections, Global section and Directory Entries. Parameter Data is
/// tokenized per entity by [`IgesFile::parameters`].
pub fn parse_with<'a>(text: &'a str, limits: &Limits) -> Result<IgesFile<'a>, ParseError> {
    let mut warnings = Vec::new();
    let sections = records::split(text, limits, &mut warnings)?;
    let global = Global::parse(&sections.global, &mut warnings)?;
    let d = &sections.directory;
    if d.len() % 2 != 0 {
        let last = d.last().map_or((0, 0), |r| (r.sequence, r.line));
        return Err(ParseError::new(ErrorKind::OddDirectory(d.len()), 'D', last.0).at_line(last.1));
    }
    if d.len() / 2 > limits.max_entities {
        return Err(ParseError::new(
            ErrorKind::Limit(format!(
                "{} directory entries, above the limit of {}",
                d.len() / 2,
                limits.max_entities
            )),
            'D',
            0,
        ));
    }
    let entries = d
        .chunks_exact(2)
        .enumerate()
        .map(|(i, pair)| DirectoryEntry::parse(&pair[0], &pair[1], 2 * i + 1))
        .collect();
    let start = sections
        .start
        .iter()
        .map(|r| r.data.trim_end())
        .collect::<Vec<_>>()
        .join("\n");
    let terminate_counts = sections
        .terminate
        .first()
        .and_then(|t| parse_terminate(t.data));
    let actual = [
        sections.start.len(),
        sections.global.len(),
        sections.directory.len(),
        sections.parameters.len(),
    ];
    match terminate_counts {
        Some(c) if c != actual => warnings.push(ParseWarning {
            code: "terminate_count",
            message: format!(
                "Terminate record declares S{} G{} D{} P{} but the file has S{} G{} D{} P{}",
                c[0], c[1], c[2], c[3], actual[0], actual[1], actual[2], actual[3]
            ),
            section: 'T',
            sequence: 1,
            de: None,
            line: sections.terminate.first().map(|r| r.line),
        }),
        None => warnings.push(ParseWarning {
            code: "terminate_count",
            message: "the Terminate record's counts are unreadable".into(),
            section: 'T',
            sequence: 1,
            de: None,
            line: sections.terminate.first().map(|r| r.line),
        }),
        _ => {}
    }
    Ok(IgesFile {
        start,
        tokenizer: global.tokenizer(),
        global,
        entries,
        warnings,
        terminate_counts,
        parameters: sections.parameters,
        limits: limits.clone(),
    })
}

/// Reads `S      1G      4D   5864P   9993`.
fn parse_terminate(data: &str) -> Option<[usize; 4]> {
    let mut out = [0usize; 4];
    for (k, letter) in ['S', 'G', 'D', 'P'].into_iter().enumerate() {
        let f = field(data, k * 8, k * 8 + 8);
        let rest = f.strip_prefix(letter)?;
        out[k] = rest.trim().parse().ok()?;
    }
    Some(out)
}

impl<'a> IgesFile<'a> {
    /// The entry whose DE pointer (odd D sequence number) is `pointer`, if it exists and
    /// parsed. Negative pointers (used in some DE fields) are taken by absolute value.
    pub fn entry(&self, pointer: i64) -> Option<&DirectoryEntry> {
        let p = usize::try_from(pointer.unsigned_abs()).ok()?;
        if p % 2 == 0 {
            return None;
        }
        self.entries.get(p / 2)?.as_ref().ok()
    }

    /// Number of Parameter Data records.
    pub fn parameter_record_count(&self) -> usize {
        self.parameters.len()
    }

    /// The tokenizer built from the Global delimiters.
    pub fn tokenizer(&self) -> Tokenizer {
        self.tokenizer
    }

    /// Whether parameter line `r`'s back-pointer names a directory entry of this file (an
    /// odd DE pointer within the D section), i.e. plausibly starts another entity's data.
    fn starts_entity(&self, r: &Record<'_>) -> bool {
        field(r.data, 65, 72)
            .trim()
            .parse::<usize>()
            .is_ok_and(|bp| bp % 2 == 1 && bp / 2 < self.entries.len())
    }

    /// The Parameter Data records of one entity and the `param_line_count` warning if any
    /// (the first half of [`IgesFile::parameters`], shared with the direct decoders).
    ///
    /// The lines are those from the DE's parameter pointer on whose back-pointer (columns
    /// 66-72) names this entity. Returns the records, the index just past them in the P
    /// section and the warnings.
    fn entity_records(
        &self,
        entry: &DirectoryEntry,
    ) -> Result<(&[Record<'a>], usize, Vec<ParseWarning>), ParseError> {
        let de = entry.pointer;
        let err = |kind| {
            ParseError::new(kind, 'D', de)
                .of_entity(de)
                .at_line(entry.line)
                .at_column(9)
        };
        let first = usize::try_from(entry.parameter_pointer)
            .ok()
            .filter(|&p| p >= 1 && p <= self.parameters.len())
            .ok_or_else(|| {
                err(ErrorKind::BadPointer {
                    what: "parameter data",
                    value: entry.parameter_pointer,
                })
            })?;
        let start = first - 1;
        // Most lines carry the pointer right-justified in columns 66-72, exactly as
        // `format!("{de:>7}")` writes it: compare the bytes first (that text parses to `de`),
        // then parse whatever else is there.
        let expected = right_justified(de);
        let owner = |r: &Record<'_>| -> bool { names(field(r.data, 65, 72), de, expected) };
        let Some(r0) = self.parameters.get(start) else {
            return Err(err(ErrorKind::BadPointer {
                what: "parameter data",
                value: entry.parameter_pointer,
            }));
        };
        if !owner(r0) {
            return Err(ParseError::new(
                ErrorKind::BackPointer {
                    found: field(r0.data, 65, 72).to_owned(),
                    expected: de,
                },
                'P',
                r0.sequence,
            )
            .at_column(66)
            .at_line(r0.line)
            .of_entity(de));
        }
        let mut end = start + 1;
        while end < self.parameters.len() && owner(&self.parameters[end]) {
            end += 1;
        }
        let records = &self.parameters[start..end];
        let mut warnings = Vec::new();
        if usize::try_from(entry.parameter_line_count).ok() != Some(records.len()) {
            warnings.push(ParseWarning {
                code: "param_line_count",
                message: format!(
                    "DE field 14 declares {} parameter lines; {} lines carry this entity's back-pointer",
                    entry.parameter_line_count,
                    records.len()
                ),
                section: 'D',
                sequence: de + 1,
                de: Some(de),
                line: Some(entry.line + 1),
            });
        }
        Ok((records, end, warnings))
    }

    /// Tokenizes the Parameter Data of one entity.
    ///
    /// The lines are those from the DE's parameter pointer on whose back-pointer (columns
    /// 66-72) names this entity; a count different from DE field 14 is a
    /// `param_line_count` warning in [`Parameters::warnings`]. The record must start with
    /// the entity type and end with the record delimiter; text after it is a comment.
    pub fn parameters(&self, entry: &DirectoryEntry) -> Result<Parameters<'_>, ParseError> {
        let de = entry.pointer;
        let (records, end, warnings) = self.entity_records(entry)?;
        let mut data = String::with_capacity(records.len() * P_DATA_COLUMNS);
        join_data(records, &mut data);
        let mut p = Parameters {
            de,
            entity_type: entry.entity_type,
            form: entry.form,
            data,
            tokens: Vec::new(),
            records,
            warnings,
        };
        let max = self.limits.max_params_per_entity;
        let mut tokens = Vec::with_capacity((p.data.len() / 8).min(max));
        self.tokenizer
            .tokenize(&p.data, 0, &mut tokens, max)
            .map_err(|e| match (&e.kind, self.parameters.get(end)) {
                // The entity's lines end where the back-pointer changes; when its data then
                // lacks the record delimiter and the next line does not start another
                // entity's data, the likely cause is a wrong back-pointer on that line:
                // name it rather than the last line read.
                (ErrorKind::Unterminated(_), Some(next)) if !self.starts_entity(next) => {
                    ParseError::new(
                        ErrorKind::BackPointer {
                            found: field(next.data, 65, 72).to_owned(),
                            expected: de,
                        },
                        'P',
                        next.sequence,
                    )
                    .at_column(66)
                    .at_line(next.line)
                    .of_entity(de)
                }
                _ => p.locate(e.offset, e.kind),
            })?;
        p.tokens = tokens;
        let ty = p.int(0, "entity type")?;
        if ty != entry.entity_type {
            return Err(p.error_at(
                0,
                ErrorKind::WrongEntity {
                    found: ty,
                    expected: entry.entity_type,
                },
            ));
        }
        Ok(p)
    }
}

/// The tokenized Parameter Data of one entity. Index 0 is the entity type; index `i` is
/// parameter `i` of the entity's table in the IGES specification.
#[derive(Debug, Clone)]
pub struct Parameters<'f> {
    /// The owning DE pointer.
    pub de: usize,
    /// Entity type (DE field 1).
    pub entity_type: i64,
    /// Form number (DE field 15).
    pub form: i64,
    data: String,
    tokens: Vec<Token>,
    records: &'f [Record<'f>],
    /// Non-fatal findings for this entity.
    pub warnings: Vec<ParseWarning>,
}

impl<'f> Parameters<'f> {
    /// Number of parameters including the entity type.
    pub fn len(&self) -> usize {
        self.tokens.len()
    }

    /// Whether there are no parameters (never true for a parsed entity).
    pub fn is_empty(&self) -> bool {
        self.tokens.is_empty()
    }

    /// The kind of parameter `i`.
    pub fn kind(&self, i: usize) -> Option<TokenKind> {
        self.tokens.get(i).map(|t| t.kind)
    }

    /// The text of parameter `i` (Hollerith strings without their `nH` prefix).
    pub fn text(&self, i: usize) -> Option<&str> {
        self.tokens.get(i).map(|t| t.text(&self.data))
    }

    /// The 1-based P sequence number, file line and column where parameter `i` starts.
    pub fn position(&self, i: usize) -> (usize, usize, usize) {
        let off = self
            .tokens
            .get(i)
            .map_or(self.data.len(), |t| t.start as usize);
        self.position_of(off)
    }

    fn position_of(&self, off: usize) -> (usize, usize, usize) {
        let idx = off / P_DATA_COLUMNS;
        let r = self.records.get(idx).or(self.records.last());
        (
            r.map_or(0, |r| r.sequence),
            r.map_or(0, |r| r.line),
            off % P_DATA_COLUMNS + 1,
        )
    }

    fn locate(&self, offset: usize, kind: ErrorKind) -> ParseError {
        let (seq, line, col) = self.position_of(offset);
        ParseError::new(kind, 'P', seq)
            .at_column(col)
            .at_line(line)
            .of_entity(self.de)
    }

    /// A located error at parameter `i` (or at the record end when `i` is past it).
    pub fn error_at(&self, i: usize, kind: ErrorKind) -> ParseError {
        let off = self.tokens.get(i).map_or_else(
            || self.tokens.last().map_or(0, |t| t.end as usize),
            |t| t.start as usize,
        );
        self.locate(off, kind)
    }

    fn bad(&self, i: usize, name: &'static str, expected: &'static str) -> ParseError {
        let found = match self.kind(i) {
            None => "<missing>".to_owned(),
            Some(TokenKind::Empty) => "<empty>".to_owned(),
            Some(_) => self.text(i).unwrap_or("").chars().take(40).collect(),
        };
        self.error_at(
            i,
            ErrorKind::BadParameter {
                index: i,
                name,
                expected,
                found,
            },
        )
    }

    /// Integer parameter `i` (required; empty is an error: counts have no default).
    pub fn int(&self, i: usize, name: &'static str) -> Result<i64, ParseError> {
        match self.tokens.get(i) {
            Some(t) if t.kind == TokenKind::Plain => {
                params::parse_int(t.text(&self.data)).ok_or_else(|| self.bad(i, name, "an integer"))
            }
            _ => Err(self.bad(i, name, "an integer")),
        }
    }

    /// Integer parameter `i`, empty = `default`.
    pub fn int_or(&self, i: usize, name: &'static str, default: i64) -> Result<i64, ParseError> {
        match self.kind(i) {
            Some(TokenKind::Empty) => Ok(default),
            _ => self.int(i, name),
        }
    }

    /// Real parameter `i`; empty = 0.0 (the IGES default); an integer token is accepted.
    pub fn real(&self, i: usize, name: &'static str) -> Result<f64, ParseError> {
        match self.tokens.get(i) {
            Some(t) if t.kind == TokenKind::Empty => Ok(0.0),
            Some(t) if t.kind == TokenKind::Plain => {
                parse_iges_real(t.text(&self.data)).map_err(|_| self.bad(i, name, "a real"))
            }
            _ => Err(self.bad(i, name, "a real")),
        }
    }

    /// Optional real parameter `i`: `None` when absent or empty.
    pub fn opt_real(&self, i: usize, name: &'static str) -> Result<Option<f64>, ParseError> {
        match self.kind(i) {
            None | Some(TokenKind::Empty) => Ok(None),
            _ => self.real(i, name).map(Some),
        }
    }

    /// String parameter `i`: `None` when empty or absent.
    pub fn string(&self, i: usize, name: &'static str) -> Result<Option<&str>, ParseError> {
        match self.kind(i) {
            None | Some(TokenKind::Empty) => Ok(None),
            Some(TokenKind::Hollerith) => Ok(self.text(i)),
            Some(TokenKind::Plain) => Err(self.bad(i, name, "a Hollerith string")),
        }
    }

    /// Reads `count` reals starting at parameter `from` into `out` (no allocation when `out`
    /// has capacity).
    pub fn reals_into(
        &self,
        from: usize,
        count: usize,
        name: &'static str,
        out: &mut Vec<f64>,
    ) -> Result<(), ParseError> {
        for i in from..from.saturating_add(count) {
            out.push(self.real(i, name)?);
        }
        Ok(())
    }
}

/// Appends the data columns 1-64 of `records` to `data`, each padded with blanks to 64
/// columns: the text the parameter tokenizer reads (free format continues across records).
fn join_data(records: &[Record<'_>], data: &mut String) {
    for r in records {
        let d = field(r.data, 0, P_DATA_COLUMNS);
        data.push_str(d);
        for _ in d.len()..P_DATA_COLUMNS {
            data.push(' ');
        }
    }
}

/// `n` as a P record writes it in columns 66-72 (right-justified, blank-filled), if it fits.
fn right_justified(n: usize) -> Option<[u8; 7]> {
    let digits = n.to_string();
    7usize.checked_sub(digits.len()).map(|blanks| {
        let mut e = [b' '; 7];
        for (slot, &c) in e.iter_mut().skip(blanks).zip(digits.as_bytes()) {
            *slot = c;
        }
        e
    })
}

/// Whether a back-pointer field names entity `de`: `back_pointer(field) == Some(de)`, with
/// the common spelling (`expected`, from [`right_justified`]) compared as bytes first.
#[inline]
fn names(field: &str, de: usize, expected: Option<[u8; 7]>) -> bool {
    expected.is_some_and(|e| field.as_bytes() == e) || back_pointer(field) == Some(de)
}

/// The DE back-pointer of a P record (columns 66-72): `field.trim().parse::<usize>()`,
/// answered from the bytes when the field is blanks and digits (every line of a large file
/// goes through here; the general form handles `+`, other whitespace and errors).
fn back_pointer(field: &str) -> Option<usize> {
    // The right-justified form every writer uses (blanks, then 1 to 18 digits to the end of
    // the field) in one pass; anything else takes the general form below.
    let b = field.as_bytes();
    let first = b.iter().position(|&c| c != b' ').unwrap_or(b.len());
    if let Some(digits) = b.get(first..)
        && !digits.is_empty()
        && digits.len() <= 18
    {
        let mut v = 0usize;
        let mut all = true;
        for &c in digits {
            let d = c.wrapping_sub(b'0');
            all &= d <= 9;
            v = v.wrapping_mul(10).wrapping_add(usize::from(d));
        }
        if all {
            return Some(v);
        }
    }
    let digits = field.trim_matches(' ');
    if !digits.is_empty() && digits.len() <= 18 && digits.bytes().all(|c| c.is_ascii_digit()) {
        return Some(
            digits
                .bytes()
                .fold(0usize, |v, c| v * 10 + usize::from(c - b'0')),
        );
    }
    field.trim().parse::<usize>().ok()
}

#[cfg(test)]
mod back_pointer_tests {
    use proptest::prelude::*;

    proptest! {
        /// The byte comparison never changes the answer of the parse.
        #[test]
        fn names_is_back_pointer(de in prop_oneof![0usize..100, 0usize..100_000_000], field in "[0-9 +]{0,8}|[0-9]{7}") {
            let expected = super::right_justified(de);
            let want = super::back_pointer(&field) == Some(de);
            prop_assert_eq!(super::names(&field, de, expected), want);
            let own = format!("{de:>7}");
            prop_assert_eq!(super::names(&own, de, expected), super::back_pointer(&own) == Some(de));
            prop_assert_eq!(super::names(&own, de, expected), true);
        }
    }

    #[test]
    fn back_pointer_is_trim_then_parse() {
        for f in [
            "      1",
            "1234567",
            "   12  ",
            "",
            "       ",
            "  +12  ",
            " 1 2   ",
            "\t12",
            "12\u{a0}",
            "  -1   ",
            "0000007",
            "abc",
            "99999999999999999999",
        ] {
            assert_eq!(
                super::back_pointer(f),
                f.trim().parse::<usize>().ok(),
                "{f:?}"
            );
        }
    }
}
