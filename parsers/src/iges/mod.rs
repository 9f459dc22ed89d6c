//! # IGES 5.3 fixed-column ASCII files
//!
//! The format layer for IGES, in three parts:
//!
//! - [`grammar`]: the nom rules of the standard, by part of the file: 80-column records and
//!   sections, the Global section with its delimiters and Hollerith strings, the Directory
//!   Entry's twenty fields, free-format parameter data with both delimiters and `E`/`D`
//!   exponents. The fast leaves (the SWAR sequence-number reader, the one-pass real reader
//!   of the P section) are rules of that one grammar.
//! - [`records`]: one declaration per entity nurbsx reads (the curves 100-112 and 126, the
//!   surfaces 108, 114-122, 128 and 190-198, the 116 points and 123 directions they name, 124,
//!   the trimmed and bounded faces 102, 141, 142, 143, 144, the B-rep 186, 502, 504, 508,
//!   510, 514 and the subfigures 308, 408) and the typed record built from it; the records
//!   of the B-rep and trimmed-face entities also write themselves;
//!   [`IgesFile::decode`] is the one decoder of every declared entity.
//! - [`writer`]: typed records in, 80-column text out.
//!
//! No geometry: turning records into NURBS is left to the consumer of these records.
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
//! let curve = file.decode::<iges::records::Curve126>(entry).record?;
//! assert_eq!(curve.points[1], [1., 1., 1.]);
//! assert_eq!((curve.v0, curve.v1), (Some(0.), Some(1.)));
//! assert_eq!(curve.normal, None); // the optional normal is absent
//! # Ok::<(), iges::ParseError>(())
//! ```
//!
//! Robustness: what a count read from the file allocates is bounded by the data actually
//! present, and a record shorter than its counts declare is an error naming them; all
//! conversions are checked; one entity's bad
//! parameters give a located error for that entity only ([`IgesFile::decode`] is
//! called per entity), the others still parse.

pub mod directory;
pub mod error;
pub mod global;
pub mod grammar;
pub mod records;
pub mod writer;

pub use directory::{DirectoryEntry, Status};
pub use error::{ErrorKind, ParseError, ParseWarning, WriteError};
pub use global::Global;
pub use grammar::parameters::{Delimiters, Parameter};
pub use records::Entity;

use crate::grammar::Cause;
use crate::{Limits, Stop};
use grammar::parameters::{Error, ParameterReader};
use grammar::records::{Record, field};

/// Data columns of a Parameter Data record (1-64); 65 is blank, 66-72 the back-pointer.
pub const P_DATA_COLUMNS: usize = 64;

/// The layouts of the 322 Attribute Table Definitions read so far, by DE pointer, for
/// [`IgesFile::references_with`] (`None`: the 322 does not read).
#[derive(Debug, Clone, Default)]
pub struct AttributeLayouts(std::collections::HashMap<usize, Option<records::AttributeLayout>>);

/// A parsed IGES file: the Start text, the Global section, the Directory Entries, and
/// the Parameter Data records, which are decoded per entity on demand.
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
    delimiters: Delimiters,
    limits: Limits,
}

/// Parses an IGES file with the default [`Limits`].
pub fn parse(text: &str) -> Result<IgesFile<'_>, ParseError> {
    parse_with(text, &Limits::default(), Stop::NEVER)
}

/// Parses an IGES file: sections, Global section and Directory Entries. Parameter Data is
/// decoded per entity by [`IgesFile::decode`]. The record split and the directory scan poll
/// `stop` every [`SCAN_POLL`](crate::stop::SCAN_POLL) lines or entries and end with
/// [`ErrorKind::Stopped`] once it has fired.
pub fn parse_with<'a>(
    text: &'a str,
    limits: &Limits,
    stop: Stop<'_>,
) -> Result<IgesFile<'a>, ParseError> {
    let mut warnings = Vec::new();
    let sections = grammar::records::split(text, limits, &mut warnings, stop)?;
    let global = grammar::global::global_section(&sections.global, &mut warnings)?;
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
    let mut entries = Vec::with_capacity(d.len() / 2);
    for (i, pair) in d.chunks_exact(2).enumerate() {
        if stop.at(i + 1) {
            return Err(ParseError::new(ErrorKind::Stopped, 'D', 2 * i + 1).at_line(pair[0].line));
        }
        entries.push(grammar::directory::directory_entry(
            &pair[0],
            &pair[1],
            2 * i + 1,
        ));
    }
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
        delimiters: global.delimiters(),
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

    /// The delimiters of the Global section.
    pub fn delimiters(&self) -> Delimiters {
        self.delimiters
    }

    /// Whether parameter line `r`'s back-pointer names a directory entry of this file (an
    /// odd DE pointer within the D section), i.e. plausibly starts another entity's data.
    fn starts_entity(&self, r: &Record<'_>) -> bool {
        field(r.data, 65, 72)
            .trim()
            .parse::<usize>()
            .is_ok_and(|bp| bp % 2 == 1 && bp / 2 < self.entries.len())
    }

    /// The Parameter Data records of one entity and the `param_line_count` warning if any.
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
        // Columns 65-72 as one word: the blank column 65 and the pointer as written
        // (every line of a large file passes here; anything else goes through `names`).
        let word = expected.map(|e| {
            let mut w = [b' '; 8];
            w[1..].copy_from_slice(&e);
            u64::from_le_bytes(w)
        });
        let owner = |r: &Record<'_>| -> bool {
            let quick = r
                .data
                .as_bytes()
                .get(64..72)
                .and_then(|c| <[u8; 8]>::try_from(c).ok())
                .map(u64::from_le_bytes);
            (quick.is_some() && quick == word) || names(field(r.data, 65, 72), de, expected)
        };
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

    /// Decodes one entity into its typed record `R` (IGES 5.3 chapter 4, by
    /// [`Entity::SCHEMA`]): the one decoder of every declared entity.
    ///
    /// The lines are those from the DE's parameter pointer on whose back-pointer (columns
    /// 66-72) names this entity; a count different from DE field 14 is a
    /// `param_line_count` warning in [`Decoded::warnings`]. The record must start with the
    /// entity type and end with the record delimiter; text after it is a comment. Reals
    /// are converted where they stand, in one pass over the data.
    pub fn decode<R: Entity>(&self, entry: &DirectoryEntry) -> Decoded<R> {
        let schema = R::SCHEMA;
        let result = self.read(entry, |r| {
            if entry.entity_type != schema.entity {
                return Err(Error::format(
                    r.rest(),
                    ErrorKind::WrongEntity {
                        found: entry.entity_type,
                        expected: schema.entity,
                    },
                ));
            }
            records::read(&schema, r).map(|values| R::from_values(values, entry))
        });
        match result {
            Ok((warnings, record)) => Decoded {
                warnings,
                record: Ok(record),
            },
            Err((warnings, e)) => Decoded {
                warnings,
                record: Err(e),
            },
        }
    }

    /// The DE pointers among an entity's parameters, by its declaration ([`records::schema_of`]):
    /// `(field name, pointer, entity types the field may name)`, zero pointers left out.
    /// `None` when the entity's type has no declaration. The entities whose layout no
    /// declaration holds ([`records::Dependent`]: the 406 forms 11 and 27, the 322 and the
    /// 422) are read by their own checkers; a 422 follows the 322 its DE structure field
    /// names (read anew: see [`IgesFile::references_with`]).
    #[allow(clippy::type_complexity)]
    pub fn references(
        &self,
        entry: &DirectoryEntry,
    ) -> Option<Result<Vec<(&'static str, i64, &'static [i64])>, ParseError>> {
        self.references_with(entry, &mut AttributeLayouts::default())
    }

    /// [`IgesFile::references`], keeping the layouts of the 322 Attribute Table
    /// Definitions the 422 instances follow in `layouts`, so that each 322 is read once
    /// however many instances name it.
    ///
    /// A 422 whose DE structure field (IGES 5.3 section 4.141) names no entity, or an
    /// entity other than a 322, is an error at its DE; one naming a 322 whose own
    /// parameters do not read (its error is its own) or no directory entry (a
    /// `pointer.invalid` of the DE structure field) has no layout to check: no pointer.
    #[allow(clippy::type_complexity)]
    pub fn references_with(
        &self,
        entry: &DirectoryEntry,
        layouts: &mut AttributeLayouts,
    ) -> Option<Result<Vec<(&'static str, i64, &'static [i64])>, ParseError>> {
        if let Some(schema) = records::schema_of(entry.entity_type, entry.form) {
            return Some(
                self.read(entry, |r| records::read(schema, r).map(|v| v.pointers()))
                    .map(|(_, refs)| refs)
                    .map_err(|(_, e)| e),
            );
        }
        let dependent = records::dependent_of(entry.entity_type, entry.form)?;
        let layout: &[(i64, usize)] = match dependent {
            records::Dependent::AttributeInstance(_) => match self.attribute_layout(entry, layouts)
            {
                Ok(Some(layout)) => layout,
                Ok(None) => return Some(Ok(Vec::new())),
                Err(e) => return Some(Err(e)),
            },
            _ => &[],
        };
        Some(
            self.read(entry, |r| {
                records::read_dependent(dependent, r, layout).map(|v| v.pointers())
            })
            .map(|(_, refs)| refs)
            .map_err(|(_, e)| e),
        )
    }

    /// The layout of the 322 a 422 `entry` follows (its DE structure field, negated):
    /// `Ok(None)` when it cannot be known (the 322 does not read, or the field names no
    /// directory entry), an error when the field names no entity or one of another type.
    fn attribute_layout<'l>(
        &self,
        entry: &DirectoryEntry,
        layouts: &'l mut AttributeLayouts,
    ) -> Result<Option<&'l [(i64, usize)]>, ParseError> {
        let wrong = |kind: ErrorKind| {
            ParseError::new(kind, 'D', entry.pointer)
                .at_line(entry.line)
                .of_entity(entry.pointer)
        };
        if entry.structure >= 0 {
            return Err(wrong(ErrorKind::Arity(format!(
                "DE field 3 (structure) is {}: a 422 Attribute Table Instance names the 322 \
                 Attribute Table Definition whose layout its values follow by a negated \
                 pointer there",
                entry.structure
            ))));
        }
        let Some(definition) = self.entry(entry.structure) else {
            return Ok(None);
        };
        if definition.entity_type != 322 {
            return Err(wrong(ErrorKind::Arity(format!(
                "DE field 3 (structure) names D{}, a {} entity: a 422 Attribute Table \
                 Instance's values follow the layout of a 322 Attribute Table Definition",
                definition.pointer, definition.entity_type
            ))));
        }
        let layout = layouts.0.entry(definition.pointer).or_insert_with(|| {
            self.read(definition, |r| {
                records::attribute_layout(r, definition.form)
            })
            .ok()
            .map(|(_, layout)| layout)
        });
        Ok(layout.as_deref())
    }

    /// The parameters of any entity as the grammar cuts them (for entities without a
    /// declared record), with the `param_line_count` warning if any.
    pub fn parameters(&self, entry: &DirectoryEntry) -> Result<Parameters, ParseError> {
        let (warnings, values) = self
            .read(entry, |r| {
                let mut values = Vec::new();
                while let Some((_, p)) = r.parameter()? {
                    values.push(match p {
                        Parameter::Default => RawParameter::Default,
                        Parameter::String(s) => RawParameter::String(s.to_owned()),
                        Parameter::Value(v) => {
                            RawParameter::Value(String::from_utf8_lossy(v).into_owned())
                        }
                    });
                }
                Ok(values)
            })
            .map_err(|(_, e)| e)?;
        Ok(Parameters {
            de: entry.pointer,
            entity_type: entry.entity_type,
            form: entry.form,
            values,
            warnings,
        })
    }

    /// Finds an entity's records, joins their data columns and runs `read` after the
    /// entity type (checked against the DE); a failure becomes a located error.
    fn read<T>(
        &self,
        entry: &DirectoryEntry,
        read: impl for<'d> FnOnce(&mut ParameterReader<'d>) -> Result<T, Error<'d>>,
    ) -> Result<(Vec<ParseWarning>, T), (Vec<ParseWarning>, ParseError)> {
        let (records, end, warnings) = self.entity_records(entry).map_err(|e| (Vec::new(), e))?;
        let mut data = String::with_capacity(records.len().saturating_mul(P_DATA_COLUMNS));
        join_data(records, &mut data);
        let whole = data.as_bytes();
        let mut r = ParameterReader::new(whole, self.delimiters, self.limits.max_params_per_entity);
        let result = r.integer("entity type", None).and_then(|ty| {
            if ty == entry.entity_type {
                read(&mut r)
            } else {
                Err(Error::format(
                    whole,
                    ErrorKind::WrongEntity {
                        found: ty,
                        expected: entry.entity_type,
                    },
                ))
            }
        });
        match result {
            Ok(v) => {
                let mut warnings = warnings;
                if r.defaulted() > 0 {
                    let first = records.first().map_or((0, 0), |r| (r.sequence, r.line));
                    warnings.push(ParseWarning {
                        code: "defaulted_value",
                        message: format!(
                            "{} parameters (reals, coordinates or flags) are defaulted (empty) and \
                             read as 0; the entity's table gives them no default",
                            r.defaulted()
                        ),
                        section: 'P',
                        sequence: first.0,
                        de: Some(entry.pointer),
                        line: Some(first.1),
                    });
                }
                Ok((warnings, v))
            }
            Err(e) => {
                let e = self.locate(entry, records, end, whole, e);
                Err((warnings, e))
            }
        }
    }

    /// A grammar error in an entity's joined data as a located error: P sequence number,
    /// column and DE pointer.
    #[cold]
    fn locate(
        &self,
        entry: &DirectoryEntry,
        records: &[Record<'_>],
        end: usize,
        whole: &[u8],
        e: Error<'_>,
    ) -> ParseError {
        let de = entry.pointer;
        let mut offset = e.offset(whole);
        let kind = match e.cause {
            Cause::Format(k) => k,
            Cause::Syntax(k) => ErrorKind::Garbage(format!("{k:?} in {}", e.rule)),
        };
        match (&kind, self.parameters.get(end)) {
            // The entity's lines end where the back-pointer changes; when its data then
            // lacks the record delimiter and the next line does not start another
            // entity's data, the likely cause is a wrong back-pointer on that line:
            // name it rather than the last line read.
            (ErrorKind::Unterminated(_), Some(next)) if !self.starts_entity(next) => {
                return ParseError::new(
                    ErrorKind::BackPointer {
                        found: field(next.data, 65, 72).to_owned(),
                        expected: de,
                    },
                    'P',
                    next.sequence,
                )
                .at_column(66)
                .at_line(next.line)
                .of_entity(de);
            }
            // Point at the record delimiter, not past it.
            (ErrorKind::Truncated { .. }, _) => offset = offset.saturating_sub(1),
            _ => {}
        }
        let idx = offset / P_DATA_COLUMNS;
        let r = records.get(idx).or(records.last());
        ParseError::new(kind, 'P', r.map_or(0, |r| r.sequence))
            .at_column(offset % P_DATA_COLUMNS + 1)
            .at_line(r.map_or(0, |r| r.line))
            .of_entity(de)
    }
}

/// The outcome of decoding one entity: the warnings about its parameter lines and the
/// typed record or the located error.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded<T> {
    /// Non-fatal findings for this entity (`param_line_count`).
    pub warnings: Vec<ParseWarning>,
    /// The typed record, or the located error.
    pub record: Result<T, ParseError>,
}

/// One parameter of an entity read raw ([`IgesFile::parameters`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RawParameter {
    /// Nothing between two delimiters: the default value.
    Default,
    /// A Hollerith string's characters.
    String(String),
    /// Anything else: the trimmed text.
    Value(String),
}

/// The parameters of one entity, as the grammar cuts them. Index 0 is the entity type;
/// index `i` is parameter `i` of the entity's table in the IGES specification.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    /// The owning DE pointer.
    pub de: usize,
    /// Entity type (DE field 1).
    pub entity_type: i64,
    /// Form number (DE field 15).
    pub form: i64,
    /// The parameters after the entity type (index 0 here is parameter 1).
    pub values: Vec<RawParameter>,
    /// Non-fatal findings for this entity.
    pub warnings: Vec<ParseWarning>,
}

impl Parameters {
    /// Number of parameters including the entity type.
    pub fn len(&self) -> usize {
        self.values.len() + 1
    }

    /// Whether there are no parameters (never true: the entity type is always there).
    pub fn is_empty(&self) -> bool {
        false
    }

    fn get(&self, i: usize) -> Option<&RawParameter> {
        self.values.get(i.checked_sub(1)?)
    }

    /// Parameter `i` as a string (`None` unless it is a Hollerith string).
    pub fn string(&self, i: usize) -> Option<&str> {
        match self.get(i)? {
            RawParameter::String(s) => Some(s),
            _ => None,
        }
    }

    /// Parameter `i` as a real (section 2.2.2.3; a default is 0.0).
    pub fn real(&self, i: usize) -> Option<f64> {
        match self.get(i)? {
            RawParameter::Default => Some(0.0),
            RawParameter::Value(v) => crate::real::parse_iges_real(v).ok(),
            RawParameter::String(_) => None,
        }
    }

    /// Parameter `i` as an integer (section 2.2.2.2; a default is 0).
    pub fn int(&self, i: usize) -> Option<i64> {
        match self.get(i)? {
            RawParameter::Default => Some(0),
            RawParameter::Value(v) => grammar::parameters::integer(v.as_bytes()),
            RawParameter::String(_) => None,
        }
    }
}

/// Appends the data columns 1-64 of `records` to `data`, each padded with blanks to 64
/// columns: the text the parameter tokenizer reads (free format continues across records).
fn join_data(records: &[Record<'_>], data: &mut String) {
    data.reserve(records.len().saturating_mul(P_DATA_COLUMNS));
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
