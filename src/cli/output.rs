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
    diagnostic_line_styled(file, d, false)
}

/// [`diagnostic_line`] with the severity coloured (ANSI) when `color` is set.
pub fn diagnostic_line_styled(file: &str, d: &Diagnostic, color: bool) -> String {
    let mut s = String::from(file);
    if let Some(line) = d.location.line {
        let _ = write!(s, ":{line}");
        if let Some(col) = d.location.column {
            let _ = write!(s, ":{col}");
        }
    }
    s.push_str(": ");
    s.push_str(&bare_diagnostic_line(d, color));
    s
}

/// `severity[code]: message (entity ...)` without a file; `error: message` for the codes of
/// failures that are not about a file's content (`usage`, `io`).
pub fn bare_diagnostic_line(d: &Diagnostic, color: bool) -> String {
    let label = if matches!(d.code.as_str(), "usage" | "io") {
        severity_name(d.severity).to_owned()
    } else {
        format!("{}[{}]", severity_name(d.severity), d.code)
    };
    let mut s = if color {
        let style = severity_style(d.severity);
        format!("{}{label}{}", style.render(), style.render_reset())
    } else {
        label
    };
    let _ = write!(s, ": {}", d.message);
    let extra = location_extra(&d.location);
    if !extra.is_empty() {
        let _ = write!(s, " ({extra})");
    }
    // One diagnostic, one line: a message never breaks an annotation over lines.
    s.replace(['\n', '\r'], " ")
}

/// The colour of a severity label (as rustc and cargo: red errors, yellow warnings).
fn severity_style(s: Severity) -> anstyle::Style {
    use anstyle::{AnsiColor, Style};
    let color = match s {
        Severity::Error => AnsiColor::Red,
        Severity::Warning => AnsiColor::Yellow,
        Severity::Info => AnsiColor::Cyan,
    };
    Style::new().bold().fg_color(Some(color.into()))
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

/// A number as the shortest text that reads back to the same `f64`: positional for
/// magnitudes from 1e-4 to 1e15, else in exponent form (`1e-17`, not 0.00000000000000001).
fn num(x: f64) -> String {
    let a = x.abs();
    if x != 0.0 && !(1e-4..1e15).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A domain `[a, b]`.
fn range((a, b): (f64, f64)) -> String {
    format!("[{}, {}]", num(a), num(b))
}

/// The `info` text report (its diagnostics go to stderr).
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
    if let Some(st) = &r.structure {
        let closed = st.shells.iter().filter(|x| x.closed).count();
        let _ = writeln!(
            s,
            "parts:    {} solid(s), {} shell(s) ({closed} closed), {} face(s), {} edge(s), {} vertex(es){}",
            st.solids.len(),
            st.shells.len(),
            st.faces.len(),
            st.edges,
            st.vertices,
            if st.assemblies > 0 {
                format!(", {} assembly(ies)", st.assemblies)
            } else {
                String::new()
            }
        );
        let _ = write!(s, "area:     {}", num(st.area));
        if st.unmeasured_faces > 0 {
            let _ = write!(s, " ({} face(s) not measurable)", st.unmeasured_faces);
        }
        s.push('\n');
        for i in &st.instances {
            let m = &i.placement;
            let _ = writeln!(
                s,
                "instance {}{}: {} ({}), placement [{}], places {}",
                "  ".repeat(i.depth.saturating_sub(1)),
                i.path,
                i.product,
                i.id,
                m.iter()
                    .map(|r| r.iter().map(|x| num(*x)).collect::<Vec<_>>().join(" "))
                    .collect::<Vec<_>>()
                    .join("; "),
                if i.places.is_empty() {
                    "its sub-instances".to_owned()
                } else {
                    i.places.join(", ")
                }
            );
        }
        for solid in &st.solids {
            let _ = writeln!(
                s,
                "solid {}: {} face(s), {} shell(s), volume {}",
                solid.id,
                solid.faces,
                solid.shells,
                solid
                    .volume
                    .map_or_else(|| "not measurable".to_owned(), num)
            );
        }
        let rows: Vec<[String; 6]> = st
            .faces
            .iter()
            .map(|f| {
                [
                    f.id.clone(),
                    f.shape
                        .and_then(|x| serde_json::to_value(x).ok())
                        .and_then(|v| v.as_str().map(str::to_owned))
                        .unwrap_or_else(|| "-".to_owned()),
                    f.surface.clone().unwrap_or_else(|| "-".to_owned()),
                    f.loops.to_string(),
                    f.edges.to_string(),
                    f.area
                        .map_or_else(|| f.area_error.clone().unwrap_or_default(), num),
                ]
            })
            .collect();
        if !rows.is_empty() {
            s.push('\n');
            s.push_str(&table(
                &["face", "surface kind", "surface", "loops", "edges", "area"],
                &rows,
            ));
        }
    }
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
                        None => e.source.entity.to_string(),
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

/// The `evaluate` text report: a table with one row per parameter (the parameter and the
/// point); derivatives, normals and curvature follow each row as labelled lines whose
/// labels and numbers are aligned across the report. Numbers read back exactly.
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
    // The extra lines of each row: (label, values).
    let extras: Vec<Vec<(String, Vec<String>)>> = r
        .results
        .iter()
        .map(|x| {
            let mut lines = Vec::new();
            if let Some(d) = &x.derivatives {
                match d {
                    serde_json::Value::Array(list) => {
                        for (k, v) in list.iter().enumerate() {
                            value_lines(&format!("d{}", k + 1), v, &mut lines);
                        }
                    }
                    other => value_lines("S", other, &mut lines),
                }
            }
            if let Some(n) = &x.normal {
                lines.push(("normal".to_owned(), n.iter().map(|v| num(*v)).collect()));
            }
            if let Some(c) = &x.curvature {
                value_lines("", c, &mut lines);
            }
            lines
        })
        .collect();
    let mut widths: Vec<usize> = header.iter().map(|h| h.len()).collect();
    for row in &rows {
        for (w, c) in widths.iter_mut().zip(row) {
            *w = (*w).max(c.len());
        }
    }
    let label_width = extras
        .iter()
        .flatten()
        .map(|(l, _)| l.len())
        .max()
        .unwrap_or(0);
    let value_width = extras
        .iter()
        .flatten()
        .flat_map(|(_, v)| v.iter().map(String::len))
        .max()
        .unwrap_or(0);
    let fmt_row = |cells: &[&str]| {
        let mut l = String::new();
        for (c, w) in cells.iter().zip(&widths) {
            let _ = write!(l, "{c:>w$}  ");
        }
        l.trim_end().to_owned()
    };
    let _ = writeln!(s, "{}", fmt_row(&header));
    for (row, lines) in rows.iter().zip(&extras) {
        let cells: Vec<&str> = row.iter().map(String::as_str).collect();
        let _ = writeln!(s, "{}", fmt_row(&cells));
        for (label, values) in lines {
            let mut l = format!("    {label:<label_width$}");
            for v in values {
                let _ = write!(l, "  {v:>value_width$}");
            }
            let _ = writeln!(s, "{}", l.trim_end());
        }
    }
    s
}

/// Flattens a JSON result (numbers, arrays of numbers, objects of them) into labelled lines:
/// `S_uv` for surface derivatives, `osculating_circle.radius` for nested fields.
fn value_lines(label: &str, v: &serde_json::Value, out: &mut Vec<(String, Vec<String>)>) {
    use serde_json::Value;
    let join = |a: &str, b: &str| match (a, b) {
        ("", b) => b.to_owned(),
        ("S", b) => format!("S_{b}"),
        (a, b) => format!("{a}.{b}"),
    };
    match v {
        Value::Object(map) => {
            for (k, x) in map {
                value_lines(&join(label, k), x, out);
            }
        }
        Value::Array(items) if items.iter().all(Value::is_number) => out.push((
            label.to_owned(),
            items
                .iter()
                .map(|x| x.as_f64().map_or_else(|| x.to_string(), num))
                .collect(),
        )),
        Value::Number(n) => out.push((
            label.to_owned(),
            vec![n.as_f64().map_or_else(|| n.to_string(), num)],
        )),
        Value::Null => out.push((label.to_owned(), vec!["-".to_owned()])),
        Value::String(text) => out.push((label.to_owned(), vec![text.clone()])),
        other => out.push((label.to_owned(), vec![other.to_string()])),
    }
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

/// Text: one verdict line per file checked (the diagnostics go to stderr; files that could
/// not be read are reported there and have no verdict).
pub fn validate_text(files: &[FileValidation]) -> String {
    let mut s = String::new();
    for f in files.iter().filter(|f| f.io_error.is_none()) {
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
    let mut sarif = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "nurbsx",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules.iter().map(|r| json!({
                    "id": r,
                    "shortDescription": { "text": rule_description(r) },
                })).collect::<Vec<_>>(),
            }},
            "artifacts": files.iter().map(|f| json!({
                "location": { "uri": path_uri(&f.file) }
            })).collect::<Vec<_>>(),
            "results": results,
        }],
    });
    if let Some(uri) = project_uri() {
        sarif["runs"][0]["tool"]["driver"]["informationUri"] = json!(uri);
    }
    let mut s = serde_json::to_string_pretty(&sarif).unwrap_or_default();
    s.push('\n');
    s
}

/// The project's home page for SARIF `informationUri`: Cargo.toml's `repository` when the
/// manifest sets one (it sets none while the project has no public home); an empty value or
/// a placeholder (an `.invalid` or `example.*` host, RFC 2606) leaves the optional property
/// out rather than pointing at nothing.
pub fn project_uri() -> Option<&'static str> {
    let uri = env!("CARGO_PKG_REPOSITORY");
    let host = uri
        .split("://")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .unwrap_or("");
    let placeholder = host.is_empty()
        || host.ends_with(".invalid")
        || host.starts_with("example.")
        || host.contains(".example.");
    (!placeholder).then_some(uri)
}

/// What a diagnostic code means, for SARIF rule descriptions: the known codes by name, the
/// others by their family (the part before the first dot).
pub fn rule_description(code: &str) -> String {
    let known = match code {
        "io" => "The file could not be read (missing, unreadable or a folder).",
        "format.unknown" => "The content is neither STEP (ISO 10303-21), IGES 5.3 nor model JSON.",
        "format.empty" => "The file is empty or holds only whitespace.",
        "format.binary" => "The file is binary data, not STEP (ISO 10303-21) or IGES 5.3 text.",
        "format.other" => {
            "The file is another format (PDF, DXF, STL, ZIP, gzip, STEP-XML ...), named in the message."
        }
        "encoding.utf16" | "encoding.utf32" => {
            "The file is UTF-16/UTF-32 text; STEP (ISO 10303-21 clause 5) and IGES (5.3 section 1.4) are 8-bit text."
        }
        "format.mismatch" => "The file's declared format contradicts its content.",
        "format.extension" => {
            "The file's extension names another format than its content; it was read by its content."
        }
        "encoding.not_utf8" => "The file is not valid text in the encoding its format requires.",
        "step.syntax" => "A STEP Part 21 statement is malformed (ISO 10303-21 clause 6-10).",
        "step.structure" => {
            "The STEP file's sections are missing or out of order (ISO 10303-21 clause 5)."
        }
        "step.reference" => "A STEP instance refers to an instance that does not exist.",
        "step.reference_cycle" => "STEP instances refer to each other in a cycle.",
        "step.schema" => {
            "A STEP instance's attributes do not match its entity's declaration (count or type)."
        }
        "step.header" => {
            "The STEP HEADER section lacks FILE_DESCRIPTION, FILE_NAME or FILE_SCHEMA, in this order with their attributes (ISO 10303-21 clause 8.2)."
        }
        "step.enumeration" => {
            "A STEP enumeration value is not one of its EXPRESS type's values (ISO 10303-42)."
        }
        "knots.repeated" => {
            "A STEP knot value is written twice in a row; the distinct knots must strictly increase (ISO 10303-42)."
        }
        "pointer.invalid" => {
            "An IGES pointer names no directory entry, the second line of one, or an entity type the field does not allow."
        }
        "pointer.cycle" => "IGES entities point to each other in a cycle.",
        "defaulted_value" => {
            "IGES parameters without a default in their entity's table are left empty (read as 0)."
        }
        "iges.syntax" => "An IGES 5.3 record is malformed (fixed columns, sections, delimiters).",
        "iges.entity" => "An IGES directory entry or parameter record is inconsistent.",
        "geometry.invalid" => {
            "A B-spline curve or surface is invalid (degree, poles, knots or weights)."
        }
        "knots.invalid" => {
            "A knot vector is invalid (decreasing, non-finite or wrong multiplicity)."
        }
        "weights.invalid" => "A weight is not a finite positive number.",
        "points.invalid" => "A control point is not finite or has the wrong dimension.",
        "transform.invalid" => "An IGES 124 transformation matrix is invalid.",
        "flag_mismatch" => {
            "A B-spline flag (closed, periodic, planar, form) disagrees with the data; the data is kept."
        }
        "flag_invalid" => "A B-spline flag has a value outside the standard's range.",
        "no_bspline" => "The file holds no B-spline curve or surface, so nothing was converted.",
        "pcurve_not_written" => {
            "2-D parameter-space curves were not written: the output format has no place for them."
        }
        "trim_ignored" | "trim_not_applied" => {
            "Trimming is not converted: the untrimmed B-spline geometry is."
        }
        "topology_ignored" => "Topology (faces, edges, shells) is not converted: the geometry is.",
        "entities_skipped" => "Entities of kinds nurbsx does not convert were skipped.",
        "model_scale_ignored" => "The IGES model-space scale is reported, not applied.",
        _ => "",
    };
    if !known.is_empty() {
        return known.to_owned();
    }
    let family = code.split('.').next().unwrap_or(code);
    match family {
        "limit" => format!("A configured limit was exceeded ({code}); see `nurbsx help limits`."),
        "step" => format!("A STEP Part 21 finding ({code})."),
        "iges" => format!("An IGES 5.3 finding ({code})."),
        "verify" => format!("The re-read output deviates from the input ({code})."),
        f if f.starts_with("unit") => format!("Length units: {}.", code.replace('_', " ")),
        _ => format!(
            "A finding about the B-spline data: {}.",
            code.replace(['_', '.'], " ")
        ),
    }
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
