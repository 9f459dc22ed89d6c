//! Diagnostics: what the reader or writer noticed, with a stable code and a location.

use serde::Serialize;

/// How serious a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// Informational: a decision the tool made that the user may want to know (units applied).
    Info,
    /// The data is readable but suspicious or was interpreted (flags disagree with data).
    Warning,
    /// The entity or file is invalid; the entity was not loaded.
    Error,
}

/// Where a diagnostic points. STEP uses `line`, `column` and `entity` (`#17`); IGES uses
/// `section` (`'D'`, `'P'`, `'G'`...), `sequence` (the sequence number in that section),
/// `column` and `entity` (`D5`, the DE pointer). Unknown parts are `None`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Location {
    /// 1-based line number in the file.
    pub line: Option<usize>,
    /// 1-based column.
    pub column: Option<usize>,
    /// The entity: `#17` (STEP instance) or `D5` (IGES directory entry).
    pub entity: Option<String>,
    /// IGES section letter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section: Option<char>,
    /// IGES sequence number within the section.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequence: Option<usize>,
}

impl Location {
    /// A location that knows only a line.
    pub fn at_line(line: usize) -> Self {
        Location {
            line: Some(line),
            ..Location::default()
        }
    }

    /// A location that knows only an entity id.
    pub fn at_entity(entity: impl Into<String>) -> Self {
        Location {
            entity: Some(entity.into()),
            ..Location::default()
        }
    }
}

impl std::fmt::Display for Location {
    /// `line:column` (or `line` alone), then ` (#17)` / ` (D5, P seq 12)` when known.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut wrote = false;
        if let Some(line) = self.line {
            write!(f, "{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
            wrote = true;
        }
        let mut extra = Vec::new();
        if let Some(e) = &self.entity {
            extra.push(e.clone());
        }
        if let (Some(s), Some(n)) = (self.section, self.sequence) {
            // An IGES directory entry names itself `D5` both ways: say it once.
            let same = self.entity.as_deref() == Some(format!("{s}{n}").as_str());
            match self.column {
                _ if same && self.column.is_none() => {}
                Some(c) if self.line.is_none() => extra.push(format!("{s}{n} col {c}")),
                _ => extra.push(format!("{s}{n}")),
            }
        }
        if !extra.is_empty() {
            if wrote {
                write!(f, " ")?;
            }
            write!(f, "({})", extra.join(", "))?;
        }
        Ok(())
    }
}

/// One finding, with a stable machine-readable `code` (e.g. `knot_count_mismatch`,
/// `flag_mismatch`, `trim_ignored`, `step.syntax`) documented by the module that emits it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    /// How serious it is.
    pub severity: Severity,
    /// Stable identifier of the kind of finding.
    pub code: String,
    /// Human-readable explanation, naming the offending value or index.
    pub message: String,
    /// Where in the file.
    pub location: Location,
    /// What the finding says about the file, which decides how `validate` reports it.
    #[serde(skip)]
    pub standing: Standing,
}

/// What a diagnostic says about the file's conformance (README, "Conformance and reading").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum Standing {
    /// A finding the conformance check reports as reading does: an error that makes the
    /// entity unreadable, a legal but suspicious value, a note.
    #[default]
    Plain,
    /// A violation of the standard (a "shall" of ISO 10303-21/42 or IGES 5.3) that the
    /// reader still read with its one unambiguous meaning, losing nothing: a warning for
    /// reading (`convert`, `info`), an error for the conformance check
    /// ([`Diagnostic::for_conformance`], what `validate` reports).
    Nonconforming,
    /// Conforming content that nurbsx does not carry (an unbounded supplemental plane, an
    /// offset surface, free curves of a placed product): reading reports it at its severity,
    /// since it is lost from the output; the conformance check reports it as a note, since
    /// it says nothing against the file.
    NotCarried,
}

impl Diagnostic {
    /// An error.
    pub fn error(code: impl Into<String>, message: impl Into<String>, location: Location) -> Self {
        Diagnostic {
            severity: Severity::Error,
            code: code.into(),
            message: message.into(),
            location,
            standing: Standing::Plain,
        }
    }

    /// A warning.
    pub fn warning(
        code: impl Into<String>,
        message: impl Into<String>,
        location: Location,
    ) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            code: code.into(),
            message: message.into(),
            location,
            standing: Standing::Plain,
        }
    }

    /// A violation of the standard read anyway with its one meaning (see
    /// [`Standing::Nonconforming`]): a warning until [`Diagnostic::for_conformance`].
    pub fn nonconforming(
        code: impl Into<String>,
        message: impl Into<String>,
        location: Location,
    ) -> Self {
        Diagnostic {
            standing: Standing::Nonconforming,
            ..Diagnostic::warning(code, message, location)
        }
    }

    /// The diagnostic as the conformance check reports it: every violation of the standard
    /// is an error, whatever the reader recovered; content nurbsx does not carry is a note.
    pub fn for_conformance(mut self) -> Self {
        match self.standing {
            Standing::Plain => {}
            Standing::Nonconforming => self.severity = Severity::Error,
            Standing::NotCarried => self.severity = Severity::Info,
        }
        self
    }

    /// The same finding marked as conforming content nurbsx does not carry (see
    /// [`Standing::NotCarried`]).
    #[must_use]
    pub fn not_carried(mut self) -> Self {
        self.standing = Standing::NotCarried;
        self
    }

    /// An informational note.
    pub fn info(code: impl Into<String>, message: impl Into<String>, location: Location) -> Self {
        Diagnostic {
            severity: Severity::Info,
            code: code.into(),
            message: message.into(),
            location,
            standing: Standing::Plain,
        }
    }
}

impl std::fmt::Display for Diagnostic {
    /// `line:col: error[code]: message` (the location part as [`Location`] prints it).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Info => "info",
        };
        let loc = self.location.to_string();
        if !loc.is_empty() {
            write!(f, "{loc}: ")?;
        }
        write!(f, "{sev}[{}]: {}", self.code, self.message)
    }
}

impl std::error::Error for Diagnostic {}
