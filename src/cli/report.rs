//! The one writer of stderr: diagnostics, summaries and the final error line, filtered by
//! severity (`-q`, `-v`, `--min-severity`), coloured on request (`--color`, `NO_COLOR`) and
//! written as text or as JSON lines (`--log-format json`). Results go to stdout elsewhere;
//! nothing else in the CLI writes to stderr except the tracing logs and the progress bar.

use std::io::{self, IsTerminal, Write};

use serde_json::json;

use crate::exchange::{Diagnostic, Location, Severity};

use super::args::{ColorArg, GlobalArgs, LogFormat, SeverityArg};
use super::output;

/// How stderr output is filtered and formatted.
#[derive(Debug, Clone)]
pub struct Reporter {
    /// The least severe diagnostic shown; `None` shows none (`-qq`).
    min_severity: Option<Severity>,
    /// Whether summary lines are shown (not with `-qq`).
    summaries: bool,
    /// Whether stderr text is coloured.
    color: bool,
    /// Whether stderr lines are JSON objects.
    json: bool,
}

impl Default for Reporter {
    /// Errors and warnings, summaries, plain text.
    fn default() -> Self {
        Reporter {
            min_severity: Some(Severity::Warning),
            summaries: true,
            color: false,
            json: false,
        }
    }
}

/// Whether colour is wanted on a stream: `always`, `never`, or (auto) when the stream is a
/// terminal, `NO_COLOR` is unset or empty (no-color.org) and `TERM` is not `dumb`.
pub fn color_wanted(choice: ColorArg, is_terminal: bool) -> bool {
    match choice {
        ColorArg::Always => true,
        ColorArg::Never => false,
        ColorArg::Auto => {
            is_terminal
                && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
                && std::env::var_os("TERM").is_none_or(|t| t != "dumb")
        }
    }
}

/// The minimum severity from the flags: `--min-severity` wins, then `-q` (errors), then
/// `-v` (info notes too); the default shows errors and warnings. `-qq` shows none.
fn min_severity(g: &GlobalArgs) -> Option<Severity> {
    match (g.min_severity, g.quiet, g.verbose) {
        (Some(SeverityArg::Error), ..) => Some(Severity::Error),
        (Some(SeverityArg::Warning), ..) => Some(Severity::Warning),
        (Some(SeverityArg::Info), ..) => Some(Severity::Info),
        (None, 0, 0) => Some(Severity::Warning),
        (None, 0, _) => Some(Severity::Info),
        (None, 1, _) => Some(Severity::Error),
        (None, _, _) => None,
    }
}

impl Reporter {
    /// The reporter the global flags ask for.
    pub fn from_args(g: &GlobalArgs) -> Self {
        Reporter {
            min_severity: min_severity(g),
            summaries: g.quiet < 2,
            color: color_wanted(g.color, io::stderr().is_terminal()),
            json: g.log_format == LogFormat::Json,
        }
    }

    /// A JSON-lines reporter with the default filter, for errors met before the flags are
    /// parsed (`--log-format json` found among the raw arguments).
    pub fn json_only() -> Self {
        Reporter {
            json: true,
            ..Reporter::default()
        }
    }

    /// A reporter that shows nothing (unit tests).
    #[cfg(test)]
    pub fn silent() -> Self {
        Reporter {
            min_severity: None,
            summaries: false,
            ..Reporter::default()
        }
    }

    /// Whether stderr carries JSON lines only (no progress bar then).
    pub fn json(&self) -> bool {
        self.json
    }

    /// Whether stderr is coloured (the tracing logs follow it).
    pub fn color(&self) -> bool {
        self.color
    }

    /// Whether a diagnostic of this severity is shown (on stderr or in a JSON document).
    pub fn shows(&self, severity: Severity) -> bool {
        self.min_severity.is_some_and(|min| severity >= min)
    }

    /// The diagnostics a JSON/JUnit/SARIF document carries: those at or above the minimum.
    pub fn filter(&self, diagnostics: &[Diagnostic]) -> Vec<Diagnostic> {
        diagnostics
            .iter()
            .filter(|d| self.shows(d.severity))
            .cloned()
            .collect()
    }

    /// Prints the diagnostics of a file that pass the filter.
    pub fn diagnostics(&self, file: &str, diagnostics: &[Diagnostic]) {
        let mut err = io::stderr().lock();
        for d in diagnostics.iter().filter(|d| self.shows(d.severity)) {
            let _ = writeln!(err, "{}", self.render(Some(file), d));
        }
    }

    /// Prints one diagnostic if it passes the filter.
    pub fn diagnostic(&self, file: Option<&str>, d: &Diagnostic) {
        if self.shows(d.severity) {
            let _ = writeln!(io::stderr().lock(), "{}", self.render(file, d));
        }
    }

    /// Prints a summary line (what a command read, wrote, verified), unless `-qq`.
    pub fn summary(&self, message: &str) {
        if !self.summaries {
            return;
        }
        let line = if self.json {
            json!({ "type": "summary", "message": message }).to_string()
        } else {
            message.to_owned()
        };
        let _ = writeln!(io::stderr().lock(), "{line}");
    }

    /// Prints the line that explains a failing exit code (always shown).
    pub fn fatal(&self, file: Option<&str>, d: &Diagnostic) {
        let _ = writeln!(io::stderr().lock(), "{}", self.render(file, d));
    }

    /// A diagnostic as one stderr line: `file:line:col: severity[code]: message` (coloured
    /// severity on request), or a JSON object with `type`, `file`, `severity`, `code`,
    /// `message` and `location`.
    pub fn render(&self, file: Option<&str>, d: &Diagnostic) -> String {
        if self.json {
            let mut value = json!({
                "type": "diagnostic",
                "severity": d.severity,
                "code": d.code,
                "message": d.message,
                "location": d.location,
            });
            if let Some(f) = file {
                value["file"] = json!(f);
            }
            return value.to_string();
        }
        match file {
            Some(f) => output::diagnostic_line_styled(f, d, self.color),
            None => output::bare_diagnostic_line(d, self.color),
        }
    }
}

/// A located error diagnostic with no location (usage and I/O failures).
pub fn error(code: &str, message: impl Into<String>) -> Diagnostic {
    Diagnostic::error(code, message, Location::default())
}
