//! Rendering: diagnostic lines, the `info` and `evaluate` text tables, and the `validate`
//! reports in text, JSON, JUnit XML and SARIF 2.1.0. Pure functions from reports to text.

use std::fmt::Write as _;

use serde::Serialize;
use serde_json::json;

use crate::exchange::{Diagnostic, Location, Severity};
use crate::pipeline::{EvalReport, InfoReport, ValidationReport};

/// The lower-case severity name.
pub fn severity_name(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Info => "info",
    }
}

/// `file:line:col: severity[code]: message`, or `file: severity[code]: message` when the line
/// is unknown (the form compilers use, which CI annotation matchers recognise). The entity
/// (`#17`, `D5`) and IGES section position follow in parentheses when known.
pub fn diagnostic_line(file: &str, d: &Diagnostic) -> String {
    let mut s = String::from(file);
    if let Some(line) = d.location.line {
        let _ = write!(s, ":{line}");
        if let Some(col) = d.location.column {
            let _ = write!(s, ":{col}");
        }
    }
    let _ = write!(
        s,
        ": {}[{}]: {}",
        severity_name(d.severity),
        d.code,
        d.message
    );
    let extra = location_extra(&d.location);
    if !extra.is_empty() {
        let _ = write!(s, " ({extra})");
    }
    // One diagnostic, one line: a message never breaks an annotation over lines.
    s.replace(['\n', '\r'], " ")
}

/// The entity and IGES section/sequence of a location, e.g. `entity #17` or `entity D5, P12`.
fn location_extra(loc: &Location) -> String {
    let mut parts = Vec::new();
    if let Some(e) = &loc.entity {
        parts.push(format!("entity {e}"));
    }
    if let (Some(sec), Some(seq)) = (loc.section, loc.sequence) {
        // A directory entry's own location (`D5`) is already named by the entity.
        let same = loc.entity.as_deref() == Some(format!("{sec}{seq}").as_str());
        match (loc.line, loc.column) {
            (None, Some(c)) => parts.push(format!("{sec}{seq} col {c}")),
            _ if same => {}
            _ => parts.push(format!("{sec}{seq}")),
        }
    }
    parts.join(", ")
}

/// A number as Rust prints `f64`: the shortest text that reads back to the same value.
fn num(x: f64) -> String {
    format!("{x}")
}

/// A domain `[a, b]`.
fn range((a, b): (f64, f64)) -> String {
    format!("[{}, {}]", num(a), num(b))
}

/// The `info` text report.
pub fn info_text(file: &str, r: &InfoReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "file:     {file}");
    let _ = writeln!(s, "format:   {}", r.format);
    if let Some(schema) = &r.schema {
        let _ = writeln!(s, "schema:   {schema}");
    }
    let _ = writeln!(s, "units:    {} ({} mm)", r.units.name, num(r.units.to_mm));
    let curves = r.entities.iter().filter(|e| e.kind == "curve").count();
    let _ = writeln!(
        s,
        "entities: {} ({} curves, {} surfaces)",
        r.entities.len(),
        curves,
        r.entities.len() - curves
    );
    if !r.entities.is_empty() {
        let rows: Vec<[String; 9]> = r
            .entities
            .iter()
            .map(|e| {
                let join =
                    |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>().join("x");
                [
                    e.id.clone(),
                    e.kind.to_owned(),
                    format!("{}D", e.dimension),
                    join(&e.degree),
                    join(&e.poles),
                    e.layout.join("/"),
                    if e.rational { "rational" } else { "polynomial" }.to_owned(),
                    e.domain
                        .iter()
                        .map(|d| range(*d))
                        .collect::<Vec<_>>()
                        .join(" x "),
                    match e.source.line {
                        Some(l) => format!("{} (line {l})", e.source.entity),
                        None => e.source.entity.clone(),
                    },
                ]
            })
            .collect();
        let header = [
            "id", "kind", "dim", "degree", "poles", "knots", "weights", "domain", "source",
        ];
        s.push('\n');
        s.push_str(&table(&header, &rows));
    }
    if !r.diagnostics.is_empty() {
        let _ = writeln!(s, "\ndiagnostics: {}", r.diagnostics.len());
        for d in &r.diagnostics {
            let _ = writeln!(s, "{}", diagnostic_line(file, d));
        }
    }
    s
}

/// A left-aligned text table with two spaces between columns (the last column unpadded).
fn table<const N: usize>(header: &[&str; N], rows: &[[String; N]]) -> String {
    let mut widths = header.map(str::len);
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let mut s = String::new();
    let mut line = |cells: Vec<&str>| {
        let mut l = String::new();
        for (i, (cell, w)) in cells.iter().zip(widths).enumerate() {
            if i + 1 == N {
                l.push_str(cell);
            } else {
                let _ = write!(l, "{cell:<w$}  ");
            }
        }
        s.push_str(l.trim_end());
        s.push('\n');
    };
    line(header.to_vec());
    for row in rows {
        line(row.iter().map(String::as_str).collect());
    }
    s
}

/// The `evaluate` text report: one row per parameter with the point, then any derivative,
/// normal and curvature values.
pub fn eval_text(r: &EvalReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "entity {}", r.entity);
    let params = r.results.first().map_or(1, |x| x.at.len());
    let dim = r.results.first().map_or(3, |x| x.point.len());
    let mut header: Vec<&str> = if params == 2 {
        vec!["u", "v"]
    } else {
        vec!["u"]
    };
    header.extend(["x", "y", "z"].iter().take(dim));
    let rows: Vec<Vec<String>> = r
        .results
        .iter()
        .map(|x| x.at.iter().chain(&x.point).map(|v| num(*v)).collect())
        .collect();
    let mut widths: Vec<usize> = header.iter().map(|h| h.len()).collect();
    for row in &rows {
        for (w, c) in widths.iter_mut().zip(row) {
            *w = (*w).max(c.len());
        }
    }
    let fmt_row = |cells: &[&str]| {
        let mut l = String::new();
        for (c, w) in cells.iter().zip(&widths) {
            let _ = write!(l, "{c:>w$}  ");
        }
        l.trim_end().to_owned()
    };
    let _ = writeln!(s, "{}", fmt_row(&header));
    for (row, x) in rows.iter().zip(&r.results) {
        let cells: Vec<&str> = row.iter().map(String::as_str).collect();
        let _ = writeln!(s, "{}", fmt_row(&cells));
        if let Some(d) = &x.derivatives {
            let _ = writeln!(s, "    derivatives: {d}");
        }
        if let Some(n) = &x.normal {
            let _ = writeln!(
                s,
                "    normal: [{}, {}, {}]",
                num(n[0]),
                num(n[1]),
                num(n[2])
            );
        }
        if let Some(c) = &x.curvature {
            let _ = writeln!(s, "    curvature: {c}");
        }
    }
    s
}

/// The result of validating one file, or the I/O error that prevented it.
#[derive(Debug, Clone, Serialize)]
pub struct FileValidation {
    /// The file as named on the command line.
    pub file: String,
    /// The report, when the file could be read.
    #[serde(flatten)]
    pub report: ValidationReport,
    /// The I/O or usage error that kept the file from being checked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub io_error: Option<String>,
}

/// Text: one line per diagnostic, then a summary line per file.
pub fn validate_text(files: &[FileValidation]) -> String {
    let mut s = String::new();
    for f in files {
        if let Some(e) = &f.io_error {
            let _ = writeln!(s, "{}: error[io]: {e}", f.file);
            continue;
        }
        for d in &f.report.diagnostics {
            let _ = writeln!(s, "{}", diagnostic_line(&f.file, d));
        }
        let r = &f.report;
        let _ = writeln!(
            s,
            "{}: {} ({} entities, {} errors, {} warnings)",
            f.file,
            if r.valid { "valid" } else { "INVALID" },
            r.entities,
            r.errors,
            r.warnings
        );
    }
    s
}

/// JSON: an array of per-file reports.
pub fn validate_json(files: &[FileValidation]) -> String {
    let mut s = serde_json::to_string_pretty(files).unwrap_or_else(|e| {
        json!({"error": format!("cannot serialise the report: {e}")}).to_string()
    });
    s.push('\n');
    s
}

/// Escapes text for XML 1.0 content and attribute values; characters XML 1.0 cannot carry
/// (most C0 controls) become U+FFFD.
pub fn xml_escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            '\t' | '\n' | '\r' => s.push(c),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => s.push('\u{FFFD}'),
            c => s.push(c),
        }
    }
    s
}

/// JUnit XML: one `<testcase>` per file; invalid files carry a `<failure>` listing the
/// diagnostics, unreadable ones an `<error>`; warnings of valid files go to `<system-out>`.
pub fn validate_junit(files: &[FileValidation]) -> String {
    let failures = files
        .iter()
        .filter(|f| f.io_error.is_none() && !f.report.valid)
        .count();
    let errors = files.iter().filter(|f| f.io_error.is_some()).count();
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        s,
        "<testsuites name=\"nurbsx validate\" tests=\"{n}\" failures=\"{failures}\" errors=\"{errors}\">\n  <testsuite name=\"nurbsx validate\" tests=\"{n}\" failures=\"{failures}\" errors=\"{errors}\" skipped=\"0\">",
        n = files.len()
    );
    for f in files {
        let name = xml_escape(&f.file);
        let _ = write!(
            s,
            "    <testcase classname=\"nurbsx.validate\" name=\"{name}\" file=\"{name}\""
        );
        let lines: String = f
            .report
            .diagnostics
            .iter()
            .map(|d| diagnostic_line(&f.file, d) + "\n")
            .collect();
        if let Some(e) = &f.io_error {
            let _ = write!(
                s,
                ">\n      <error message=\"{}\" type=\"io\">{}</error>\n    </testcase>\n",
                xml_escape(e),
                xml_escape(e)
            );
        } else if !f.report.valid {
            let r = &f.report;
            let message = format!(
                "{} errors, {} warnings in {} entities",
                r.errors, r.warnings, r.entities
            );
            let _ = write!(
                s,
                ">\n      <failure message=\"{}\" type=\"invalid\">{}</failure>\n    </testcase>\n",
                xml_escape(&message),
                xml_escape(&lines)
            );
        } else if !lines.is_empty() {
            let _ = write!(
                s,
                ">\n      <system-out>{}</system-out>\n    </testcase>\n",
                xml_escape(&lines)
            );
        } else {
            s.push_str("/>\n");
        }
    }
    s.push_str("  </testsuite>\n</testsuites>\n");
    s
}

/// A path as a URI reference for SARIF `artifactLocation.uri`: relative paths stay relative,
/// absolute ones become `file://` URIs; backslashes become `/`; unreserved characters and
/// `/` stay, everything else is percent-encoded (RFC 3986).
pub fn path_uri(path: &str) -> String {
    let slashed = path.replace('\\', "/");
    let drive = slashed.as_bytes().get(1) == Some(&b':');
    let mut s = match (slashed.starts_with('/'), drive) {
        (true, _) => String::from("file://"),
        (false, true) => String::from("file:///"),
        _ => String::new(),
    };
    for (i, b) in slashed.bytes().enumerate() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            s.push(char::from(b));
        } else if drive && i == 1 {
            s.push(':');
        } else {
            let _ = write!(s, "%{b:02X}");
        }
    }
    s
}

/// SARIF 2.1.0 (OASIS): one run, one rule per diagnostic code, one result per diagnostic
/// (`ruleId` = code, `level` error/warning/note, `physicalLocation` with a 1-based region
/// when the line is known, the entity as a logical location).
pub fn validate_sarif(files: &[FileValidation]) -> String {
    let mut rules: Vec<String> = Vec::new();
    let mut results = Vec::new();
    let mut add = |file: &str, code: &str, level: &str, message: &str, loc: &Location| {
        if !rules.iter().any(|r| r == code) {
            rules.push(code.to_owned());
        }
        let mut physical = json!({ "artifactLocation": { "uri": path_uri(file) } });
        if let Some(line) = loc.line.filter(|&l| l > 0) {
            let mut region = json!({ "startLine": line });
            if let Some(col) = loc.column.filter(|&c| c > 0) {
                region["startColumn"] = json!(col);
            }
            physical["region"] = region;
        }
        let mut location = json!({ "physicalLocation": physical });
        if let Some(e) = &loc.entity {
            location["logicalLocations"] = json!([{ "name": e, "kind": "object" }]);
        }
        results.push(json!({
            "ruleId": code,
            "level": level,
            "message": { "text": message },
            "locations": [location],
        }));
    };
    for f in files {
        if let Some(e) = &f.io_error {
            add(&f.file, "io", "error", e, &Location::default());
            continue;
        }
        for d in &f.report.diagnostics {
            let level = match d.severity {
                Severity::Error => "error",
                Severity::Warning => "warning",
                Severity::Info => "note",
            };
            add(&f.file, &d.code, level, &d.message, &d.location);
        }
    }
    let sarif = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "nurbsx",
                "version": env!("CARGO_PKG_VERSION"),
                "informationUri": "https://example.invalid/nurbsx",
                "rules": rules.iter().map(|r| json!({
                    "id": r,
                    "shortDescription": { "text": format!("nurbsx diagnostic {r}") },
                })).collect::<Vec<_>>(),
            }},
            "artifacts": files.iter().map(|f| json!({
                "location": { "uri": path_uri(&f.file) }
            })).collect::<Vec<_>>(),
            "results": results,
        }],
    });
    let mut s = serde_json::to_string_pretty(&sarif).unwrap_or_default();
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagnostic_lines_have_the_compiler_form() {
        let d = Diagnostic::warning(
            "flag_mismatch",
            "closed flag says .T.",
            Location {
                line: Some(12),
                column: Some(4),
                entity: Some("#17".into()),
                ..Default::default()
            },
        );
        assert_eq!(
            diagnostic_line("a.step", &d),
            "a.step:12:4: warning[flag_mismatch]: closed flag says .T. (entity #17)"
        );
        let d = Diagnostic::error("x", "two\nlines", Location::default());
        assert_eq!(diagnostic_line("b.igs", &d), "b.igs: error[x]: two lines");
    }

    #[test]
    fn xml_escaping_covers_markup_and_controls() {
        assert_eq!(
            xml_escape("a<b & \"c\" 'd'>\u{1}"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;\u{FFFD}"
        );
    }

    #[test]
    fn uris_are_percent_encoded() {
        assert_eq!(path_uri("dir/my part#1.step"), "dir/my%20part%231.step");
        assert_eq!(path_uri("a\\b.igs"), "a/b.igs");
        assert_eq!(path_uri("/tmp/a b.step"), "file:///tmp/a%20b.step");
        assert_eq!(path_uri("C:\\cad\\a.igs"), "file:///C:/cad/a.igs");
    }
}
