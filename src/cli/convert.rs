//! `nurbsx convert`: one file with `-o`, or a batch with `--out-dir` ([`super::batch`]).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::exchange::{Diagnostic, ExportOptions, Format, Severity};
use crate::pipeline::{self, ClampPolicy, ConvertReport, ConvertRequest, InputKind, Settings};

use super::args::{ConvertArgs, FormatArg};
use super::{
    CliError, Context, Outcome, batch, display_name, extension_warning, is_dash, outcome_of,
    output, read_input, write_output,
};

/// What one conversion did, as written to `--report` (pretty JSON for one file, one JSON
/// line per file for a batch).
#[derive(Debug, Clone, Serialize)]
pub struct FileRecord {
    /// The input as named (or found in a folder).
    pub file: String,
    /// The output written (`None` when the conversion failed before writing).
    pub output: Option<String>,
    /// Whether the file converted (and verified, with `--verify`).
    pub ok: bool,
    /// `step`, `iges` or `json`, once known.
    pub input_format: Option<String>,
    /// `step` or `iges`, once known.
    pub output_format: Option<String>,
    /// Entities converted.
    pub entities: usize,
    /// Diagnostic counts by severity.
    pub diagnostics: Counts,
    /// The error, as one `file:line:col: error[code]: message` line.
    pub error: Option<String>,
    /// The error's stable code.
    pub error_code: Option<String>,
    /// With `--verify`: the largest deviation found relative to entity size.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_relative_deviation: Option<f64>,
    /// The pipeline's full report (diagnostics, per-entity verification).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub report: Option<ConvertReport>,
}

/// Diagnostics by severity.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Counts {
    /// Errors.
    pub errors: usize,
    /// Warnings.
    pub warnings: usize,
    /// Informational notes.
    pub infos: usize,
}

impl Counts {
    /// Counts a list of diagnostics.
    pub fn of(diagnostics: &[Diagnostic]) -> Self {
        let mut c = Counts::default();
        for d in diagnostics {
            match d.severity {
                Severity::Error => c.errors += 1,
                Severity::Warning => c.warnings += 1,
                Severity::Info => c.infos += 1,
            }
        }
        c
    }
}

/// The planned conversion settings shared by single and batch mode.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The pipeline request (without `to` for a batch without `--to`).
    pub request: ConvertRequest,
    /// Limits and import policies.
    pub settings: Settings,
}

/// Runs `nurbsx convert`.
pub fn run(ctx: &Context, a: ConvertArgs) -> Result<Outcome, CliError> {
    let mut settings = ctx.settings.clone();
    settings.import.trim_to_parameter_range = a.trim_to_range;
    settings.import.geometry_only = a.geometry_only;
    settings.import.sew_tolerance = a.sew_tolerance;
    settings.strict = a.strict;
    let request = ConvertRequest {
        to: a.to.map(format_of),
        export: ExportOptions {
            schema: a.schema.into(),
            units: a.units.0,
            timestamp: a.timestamp.clone(),
            iges_brep: a.iges_brep,
            flatten_assemblies: a.flatten_assemblies,
            ..ExportOptions::default()
        },
        clamp: if a.clamp {
            ClampPolicy::Clamp
        } else if a.unclamp {
            ClampPolicy::Unclamp
        } else {
            ClampPolicy::Keep
        },
        verify: a.verify,
    };
    let plan = Plan { request, settings };
    let is_batch = a.out_dir.is_some() || a.inputs.len() > 1 || a.inputs.iter().any(|p| p.is_dir());
    if is_batch {
        let Some(out_dir) = &a.out_dir else {
            return Err(CliError::Usage(
                "several inputs or a folder need --out-dir DIR (and usually --to step|iges)".into(),
            ));
        };
        if a.inputs.iter().any(|p| is_dash(p)) {
            return Err(CliError::Usage(
                "standard input (`-`) cannot be part of a batch".into(),
            ));
        }
        return batch::run(
            ctx,
            &a.inputs,
            out_dir,
            &plan,
            batch::Options {
                report: a.report.as_deref(),
                jobs: a.jobs.map(usize::from),
                on_collision: a.on_collision,
            },
        );
    }
    let (Some(input), Some(out)) = (a.inputs.first(), a.output.as_ref()) else {
        return Err(CliError::Usage(
            "give the output file with -o OUT (or --out-dir DIR for a batch)".into(),
        ));
    };
    single(ctx, input, out, plan, a.report.as_deref())
}

/// The exchange format of a `--to` value.
pub fn format_of(f: FormatArg) -> Format {
    match f {
        FormatArg::Step => Format::Step,
        FormatArg::Iges => Format::Iges,
    }
}

/// `STEP` or `IGES`.
fn format_label(f: Format) -> &'static str {
    match f {
        Format::Step => "STEP",
        Format::Iges => "IGES",
    }
}

/// The output format named by OUT's extension; `Ok(None)` when there is no extension (or
/// OUT is `-`); an error for `.json` and unknown extensions.
fn format_from_output(out: &Path) -> Result<Option<Format>, CliError> {
    if is_dash(out) || out.extension().is_none() {
        return Ok(None);
    }
    match InputKind::from_path(out) {
        Some(InputKind::Json) => Err(CliError::Usage(format!(
            "convert writes STEP or IGES, not model JSON (`{}`); `nurbsx info --json` shows \
             the geometry as JSON",
            out.display()
        ))),
        Some(kind) => Ok(kind.format()),
        None => Err(CliError::Usage(format!(
            "cannot tell the output format from `{}`: use .step/.stp/.p21 or .igs/.iges, or \
             give --to step|iges",
            out.display()
        ))),
    }
}

/// Converts one file.
fn single(
    ctx: &Context,
    input: &Path,
    out: &Path,
    mut plan: Plan,
    report_path: Option<&Path>,
) -> Result<Outcome, CliError> {
    match plan.request.to {
        None => plan.request.to = format_from_output(out)?,
        Some(to) => {
            // --to wins over the extension; a contradiction is worth a word.
            if let Ok(Some(ext)) = format_from_output(out) {
                if ext != to {
                    ctx.report.diagnostic(
                        Some(&display_name(out)),
                        &Diagnostic::warning(
                            "format.extension",
                            format!(
                                "writing {} as --to asks, despite the extension",
                                format_label(to)
                            ),
                            Default::default(),
                        ),
                    );
                }
            }
        }
    }
    if let Some(name) = out.file_name().and_then(|n| n.to_str()) {
        plan.request.export.file_name = name.to_owned();
    }
    let name = display_name(input);
    let (bytes, hint) = read_input(input, &plan.settings)?;
    let result = convert_bytes(input, &bytes, hint, &plan);
    let record = match &result {
        Ok(Converted::Written(o)) => success_record(&name, Some(display_name(out)), &o.report),
        Ok(Converted::Empty(diagnostics)) => empty_record(&name, hint, diagnostics),
        Err(e) => failure_record(&name, e.diagnostic.clone(), hint),
    };
    let write_record = || match report_path {
        Some(path) => write_report(path, &record),
        None => Ok(()),
    };
    let output = match result {
        Ok(Converted::Written(o)) => o,
        Ok(Converted::Empty(diagnostics)) => {
            write_record()?;
            ctx.report.diagnostics(&name, &diagnostics);
            return Ok(outcome_of(&diagnostics));
        }
        Err(e) => {
            write_record()?;
            return Err(CliError::pipeline(input, e));
        }
    };
    ctx.report.diagnostics(&name, &output.report.diagnostics);
    write_output(out, &output.text)?;
    write_record()?;
    ctx.report.summary(&summary(
        &name,
        &display_name(out),
        &output.report,
        plan.request.verify,
    ));
    if let Some(devs) = &output.report.verify {
        // Per entity, shown with -v.
        for d in devs {
            ctx.report.diagnostic(
                Some(&name),
                &Diagnostic::info(
                    "verify.entity",
                    format!(
                        "{} -> {}: max deviation {:e} (relative {:e})",
                        d.input_id, d.output_id, d.max_deviation, d.relative
                    ),
                    Default::default(),
                ),
            );
        }
    }
    tracing::info!(
        input = %name,
        output = %display_name(out),
        entities = output.report.entities_out,
        "converted"
    );
    Ok(outcome_of(&output.report.diagnostics))
}

/// What a conversion gave: a file, or nothing because the input holds no B-spline entity
/// (with the diagnostics that say so).
pub enum Converted {
    /// The converted file and its report.
    Written(Box<pipeline::ConvertOutput>),
    /// No B-spline entity: nothing to write. The diagnostics end with `no_bspline`.
    Empty(Vec<Diagnostic>),
}

/// Converts the bytes of one input (single and batch mode alike): warns when the extension
/// contradicts the content, and turns an input without any B-spline entity into
/// [`Converted::Empty`] (a warning, as `validate` says it, not a failure) unless the reader
/// found errors (then the file is invalid, exit 1).
pub fn convert_bytes(
    path: &Path,
    bytes: &[u8],
    hint: Option<InputKind>,
    plan: &Plan,
) -> Result<Converted, pipeline::PipelineError> {
    let warning = InputKind::sniff(bytes).and_then(|kind| extension_warning(path, kind));
    match pipeline::convert(bytes, hint, &plan.request, &plan.settings) {
        Ok(mut o) => {
            if let Some(w) = warning {
                o.report.diagnostics.insert(0, w);
            }
            Ok(Converted::Written(Box::new(o)))
        }
        Err(e) if e.code() == "convert.empty" => {
            // Read again for the diagnostics that say why nothing was found.
            let loaded = pipeline::load(bytes, hint, &plan.settings)?;
            let mut diagnostics: Vec<Diagnostic> = warning.into_iter().collect();
            let found = loaded.document.diagnostics.len();
            diagnostics.extend(loaded.document.diagnostics);
            if !diagnostics.iter().any(|d| d.severity == Severity::Error) {
                diagnostics.push(super::inspect::no_bspline_warning(found));
            }
            Ok(Converted::Empty(diagnostics))
        }
        Err(e) => Err(e),
    }
}

/// The summary line of one conversion: what was read, written, left out and verified.
pub fn summary(input: &str, out: &str, r: &ConvertReport, tolerance: Option<f64>) -> String {
    let left_out = r.entities_in.saturating_sub(r.entities_out);
    let mut s = format!(
        "{input} -> {out}: read {} curves and surfaces, wrote {} as {}",
        r.entities_in,
        r.entities_out,
        r.output_format.to_ascii_uppercase()
    );
    if left_out > 0 {
        s.push_str(&format!(
            ", left out {left_out} (2-D parameter-space curves: see the pcurve_not_written warning)"
        ));
    }
    if let Some(p) = &r.verify_part {
        s.push_str(&format!(
            "; verified the part as re-read: {} faces, {} solids",
            p.faces_out, p.solids_out
        ));
        if p.measured {
            s.push_str(&format!(
                ", area relative deviation {:e}, volume {:e}, centroid {:e} of the size \
                 (tolerance {:e})",
                p.area_relative,
                p.volume_relative,
                p.centroid_relative,
                tolerance.unwrap_or_default()
            ));
        } else {
            s.push_str(" (areas not compared: see the verify.unmeasured warning)");
        }
    } else if let Some(devs) = &r.verify {
        let worst = devs.iter().map(|d| d.relative).fold(0.0, f64::max);
        s.push_str(&format!(
            "; verified {} written entities against the input: largest relative deviation \
             {worst:e} (tolerance {:e})",
            devs.len(),
            tolerance.unwrap_or_default()
        ));
    }
    s
}

/// The record of a successful conversion.
pub fn success_record(file: &str, output: Option<String>, report: &ConvertReport) -> FileRecord {
    FileRecord {
        file: file.to_owned(),
        output,
        ok: true,
        input_format: Some(report.input_format.clone()),
        output_format: Some(report.output_format.clone()),
        entities: report.entities_out,
        diagnostics: Counts::of(&report.diagnostics),
        error: None,
        error_code: None,
        max_relative_deviation: report
            .verify
            .as_ref()
            .map(|v| v.iter().map(|d| d.relative).fold(0.0, f64::max)),
        report: Some(report.clone()),
    }
}

/// The record of an input without B-spline entities: nothing written, not a failure.
pub fn empty_record(file: &str, hint: Option<InputKind>, diagnostics: &[Diagnostic]) -> FileRecord {
    FileRecord {
        file: file.to_owned(),
        output: None,
        ok: true,
        input_format: hint.map(|k| k.name().to_owned()),
        output_format: None,
        entities: 0,
        diagnostics: Counts::of(diagnostics),
        error: None,
        error_code: None,
        max_relative_deviation: None,
        report: None,
    }
}

/// The record of a failed conversion.
pub fn failure_record(file: &str, error: Diagnostic, hint: Option<InputKind>) -> FileRecord {
    FileRecord {
        file: file.to_owned(),
        output: None,
        ok: false,
        input_format: hint.map(|k| k.name().to_owned()),
        output_format: None,
        entities: 0,
        diagnostics: Counts::of(std::slice::from_ref(&error)),
        error: Some(output::diagnostic_line(file, &error)),
        error_code: Some(error.code.clone()),
        max_relative_deviation: None,
        report: None,
    }
}

/// Writes a single-file report as pretty JSON.
fn write_report(path: &Path, record: &FileRecord) -> Result<(), CliError> {
    let mut text = serde_json::to_string_pretty(record)
        .map_err(|e| CliError::Usage(format!("cannot serialise the report: {e}")))?;
    text.push('\n');
    write_output(path, &text)
}

/// The output path of a batch input: `out_dir/relative` with the target's extension.
pub fn batch_output_path(out_dir: &Path, relative: &Path, to: Option<Format>) -> PathBuf {
    let mut path = out_dir.join(relative);
    match to {
        Some(Format::Step) => {
            path.set_extension("step");
        }
        Some(Format::Iges) => {
            path.set_extension("igs");
        }
        None => {}
    }
    path
}
