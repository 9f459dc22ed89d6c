//! Located IGES errors and warnings.
//!
//! Every error names the section letter (`S`, `G`, `D`, `P`, `T`), the sequence number of
//! the record within that section (IGES 5.3 section 2.1: columns 74-80), the 1-based column
//! inside that record when known, the owning Directory Entry pointer when the problem
//! belongs to one entity, and the 1-based line of the file.

use std::fmt;

/// What went wrong (the location is in [`ParseError`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// A required section (G, D, P or T) is absent.
    #[error("the {0} section is missing")]
    MissingSection(char),
    /// A record belongs to a section that may not follow the previous one (order S G D P T).
    #[error(
        "a {found} record follows the {after} section (sections must come in the order S, G, D, P, T)"
    )]
    SectionOrder {
        /// The section letter found.
        found: char,
        /// The section it follows.
        after: char,
    },
    /// A record has no recognisable section letter and sequence number in columns 73-80.
    #[error("record has no section letter and sequence number in columns 73-80")]
    BadRecord,
    /// The compressed ASCII form (C section) is not supported.
    #[error("compressed ASCII IGES (flag section C) is not supported")]
    Compressed,
    /// The Directory Entry section has an odd number of records.
    #[error("the D section has {0} records; directory entries take two records each")]
    OddDirectory(usize),
    /// A fixed-column field that must hold an integer does not.
    #[error("field {field} ({name}) is not an integer: {text:?}")]
    BadField {
        /// DE field number (1-20).
        field: u8,
        /// Field name.
        name: &'static str,
        /// The field text.
        text: String,
    },
    /// The two records of a Directory Entry name different entity types.
    #[error("entity type {first} on the first DE record but {second} on the second")]
    TypeMismatch {
        /// Field 1.
        first: i64,
        /// Field 11.
        second: i64,
    },
    /// The Global section's first parameters do not define valid delimiters.
    #[error("bad delimiter definition: {0}")]
    BadDelimiter(String),
    /// A Hollerith string's declared length runs past the end of the data.
    #[error("Hollerith string declares {declared} characters but only {available} remain")]
    HollerithTooLong {
        /// The declared count.
        declared: usize,
        /// Characters left in the record.
        available: usize,
    },
    /// Something other than a delimiter follows a parameter.
    #[error("unexpected {0:?} after a parameter (expected a delimiter)")]
    Garbage(String),
    /// The parameter record has no record delimiter.
    #[error("the parameter record is not terminated by the record delimiter {0:?}")]
    Unterminated(char),
    /// A parameter is not of the expected type.
    #[error("parameter {index} ({name}) should be {expected}: {found:?}")]
    BadParameter {
        /// 1-based parameter index as the IGES tables number it (the entity type is 0).
        index: usize,
        /// Parameter name from the spec table.
        name: &'static str,
        /// Expected type (`an integer`, `a real`, `a string`, `0 or 1`...).
        expected: &'static str,
        /// The token as found.
        found: String,
    },
    /// A record declares more values than it holds (checked before any allocation).
    #[error("{what}: the record needs {needed} parameters but holds {present}")]
    Truncated {
        /// What the count was for.
        what: String,
        /// Parameters the declared counts need.
        needed: usize,
        /// Parameters present.
        present: usize,
    },
    /// A count or index is out of range (negative, overflowing, or beyond a limit).
    #[error("{0}")]
    OutOfRange(String),
    /// The parameters do not add up to what the entity's counts declare: data left after
    /// the entity's parameters and its associativity and property pointer groups, or a
    /// record that ends inside its optional tail (IGES 5.3 section 2.2.4.5.2).
    #[error("{0}")]
    Arity(String),
    /// A DE or parameter-data pointer points nowhere.
    #[error("{what} pointer {value} points outside the file")]
    BadPointer {
        /// Which pointer.
        what: &'static str,
        /// Its value.
        value: i64,
    },
    /// A parameter line's back-pointer (columns 66-72) names another entity.
    #[error("parameter line back-pointer {found:?} does not name this entity (D{expected})")]
    BackPointer {
        /// Text of columns 66-72.
        found: String,
        /// The owning DE pointer.
        expected: usize,
    },
    /// A resource limit was exceeded.
    #[error("limit exceeded: {0}")]
    Limit(String),
    /// The caller's [`Stop`](crate::Stop) signal fired during the scan.
    #[error("the scan was stopped by its caller")]
    Stopped,
    /// The entity has a different type than the typed record expects.
    #[error("entity type {found} is not {expected}")]
    WrongEntity {
        /// Type found.
        found: i64,
        /// Type expected.
        expected: i64,
    },
}

/// A located IGES error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ParseError {
    /// What went wrong.
    pub kind: ErrorKind,
    /// Section letter (`S`, `G`, `D`, `P`, `T`), or `' '` when unknown.
    pub section: char,
    /// Sequence number within the section (0 when unknown).
    pub sequence: usize,
    /// 1-based column inside the record.
    pub column: Option<usize>,
    /// DE pointer (odd D sequence number) of the entity concerned.
    pub de: Option<usize>,
    /// 1-based line of the file.
    pub line: Option<usize>,
}

impl ParseError {
    /// An error at a record.
    pub fn new(kind: ErrorKind, section: char, sequence: usize) -> Self {
        ParseError {
            kind,
            section,
            sequence,
            column: None,
            de: None,
            line: None,
        }
    }

    /// Sets the column.
    pub fn at_column(mut self, column: usize) -> Self {
        self.column = Some(column);
        self
    }

    /// Sets the DE pointer.
    pub fn of_entity(mut self, de: usize) -> Self {
        self.de = Some(de);
        self
    }

    /// Sets the file line.
    pub fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
}

impl fmt::Display for ParseError {
    /// `line 12, P3 col 17 (D5): <message>`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(line) = self.line {
            write!(f, "line {line}, ")?;
        }
        write!(f, "{}{}", self.section, self.sequence)?;
        if let Some(c) = self.column {
            write!(f, " col {c}")?;
        }
        if let Some(de) = self.de {
            write!(f, " (D{de})")?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// A non-fatal finding: the file is readable, but something was tolerated.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseWarning {
    /// Stable code: `crlf`, `short_line`, `long_line`, `sequence`, `missing_start`,
    /// `terminate_count`, `param_line_count`, `delimiter_form`, `global_field`,
    /// `missing_terminate`, `defaulted_value`.
    pub code: &'static str,
    /// Human-readable explanation.
    pub message: String,
    /// Section letter.
    pub section: char,
    /// Sequence number within the section.
    pub sequence: usize,
    /// DE pointer when the warning concerns one entity.
    pub de: Option<usize>,
    /// 1-based line of the file.
    pub line: Option<usize>,
}

/// Why a file could not be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// A real is NaN or infinite.
    #[error("entity {entity}: cannot write non-finite real {value}")]
    NonFinite {
        /// Index of the entity in the write list (0 for the Global section).
        entity: usize,
        /// The value.
        value: f64,
    },
    /// A field does not fit its fixed columns or a delimiter is not usable.
    #[error("{0}")]
    Field(String),
}
