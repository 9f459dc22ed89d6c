//! `nurbsx info` and `nurbsx validate`.

use rayon::prelude::*;

use crate::exchange::Diagnostic;
use crate::pipeline::{self, ValidationReport};

use super::args::{InfoArgs, ValidateArgs, ValidateFormat};
use super::output::{self, FileValidation};
use super::{
    CliError, Context, Outcome, display_name, extension_warning, load_file, outcome_of,
    print_stdout, read_input,
};

/// The warning for a file that holds no B-spline curve or surface (and no error explaining
/// why): the same in `convert` and `validate`.
pub fn no_bspline_warning(diagnostics: usize) -> Diagnostic {
    Diagnostic::warning(
        "no_bspline",
        format!(
            "no curve or surface found (nurbsx reads the ISO 10303-42 and IGES 5.3 curves \
             and surfaces that have an exact NURBS form; the reader noted {diagnostics} other \
             finding(s), shown with -v); nothing to convert"
        ),
        Default::default(),
    )
}

/// `nurbsx info FILE [--json]`: the pipeline's [`InfoReport`](crate::pipeline::InfoReport)
/// as a table on stdout (diagnostics on stderr) or as one JSON document (diagnostics inside).
pub fn info(ctx: &Context, a: InfoArgs) -> Result<Outcome, CliError> {
    let name = display_name(&a.input);
    let loaded = if a.strict || a.geometry_only {
        let mut read = ctx.clone();
        read.settings.strict |= a.strict;
        read.settings.import.geometry_only = a.geometry_only;
        load_file(&read, &a.input)?
    } else {
        load_file(ctx, &a.input)?
    };
    let mut report = pipeline::info(&loaded);
    let outcome = outcome_of(&report.diagnostics);
    let text = if a.json {
        report.diagnostics = ctx.report.filter(&report.diagnostics);
        let mut s = serde_json::to_string_pretty(&report).map_err(|e| {
            CliError::Usage(format!("cannot serialise the report of `{name}`: {e}"))
        })?;
        s.push('\n');
        s
    } else {
        ctx.report.diagnostics(&name, &report.diagnostics);
        output::info_text(&name, &report)
    };
    print_stdout(&text)?;
    Ok(outcome)
}

/// `nurbsx validate FILE...`: validates every file, then prints one verdict line per file on
/// stdout (diagnostics on stderr) or one JSON/JUnit/SARIF document holding everything. A
/// file that cannot be opened makes the exit code 2.
pub fn validate(ctx: &Context, a: ValidateArgs) -> Result<Outcome, CliError> {
    let format = if a.json {
        ValidateFormat::Json
    } else {
        a.format
    };
    // Plan: folders expand to the exchange files below them.
    let mut paths = Vec::with_capacity(a.inputs.len());
    for input in &a.inputs {
        if input.is_dir() {
            paths.extend(super::batch::walk(ctx, input, None)?);
        } else {
            paths.push(input.clone());
        }
    }
    // Run: files are independent, so they are checked in parallel (order kept).
    let mut files: Vec<FileValidation> = paths
        .par_iter()
        .map(|path| check_one(ctx, path, a.strict))
        .collect();
    let io_failed = files.iter().any(|f| f.io_error.is_some());
    let all_valid = files.iter().all(|f| f.report.valid);
    if format == ValidateFormat::Text {
        for f in &files {
            match &f.io_error {
                Some(e) => ctx
                    .report
                    .fatal(None, &super::report::error("io", e.clone())),
                None => ctx.report.diagnostics(&f.file, &f.report.diagnostics),
            }
            print_stdout(&output::validate_text(std::slice::from_ref(f)))?;
        }
    } else {
        for f in &mut files {
            f.report.diagnostics = ctx.report.filter(&f.report.diagnostics);
        }
        let text = match format {
            ValidateFormat::Json => output::validate_json(&files),
            ValidateFormat::Junit => output::validate_junit(&files),
            _ => output::validate_sarif(&files),
        };
        print_stdout(&text)?;
    }
    if io_failed {
        // Exit 2 without a second message: the output already names the file.
        return Err(CliError::Quiet(2));
    }
    Ok(if all_valid {
        Outcome::Success
    } else {
        Outcome::Failure
    })
}

/// Validates one file; an I/O failure is recorded in the result.
fn check_one(ctx: &Context, path: &std::path::Path, strict: bool) -> FileValidation {
    let file = display_name(path);
    match read_input(path, &ctx.settings) {
        Ok((bytes, hint)) => {
            let mut report = pipeline::validate(&bytes, hint, strict, &ctx.settings);
            let ext = pipeline::InputKind::sniff(&bytes).and_then(|k| extension_warning(path, k));
            let empty = report.entities == 0 && report.errors == 0;
            if ext.is_some() || empty {
                let found = report.diagnostics.len();
                let mut all: Vec<Diagnostic> = ext.into_iter().collect();
                all.append(&mut report.diagnostics);
                if empty {
                    all.push(no_bspline_warning(found));
                }
                report = ValidationReport::new(report.entities, all, strict);
            }
            FileValidation {
                file,
                report,
                io_error: None,
            }
        }
        // A limit refusal is a finding about the file, not an I/O failure.
        Err(CliError::Pipeline { error, .. }) => FileValidation {
            file,
            report: ValidationReport::new(0, vec![error.diagnostic], strict),
            io_error: None,
        },
        Err(e) => FileValidation {
            file,
            report: ValidationReport::new(0, Vec::new(), strict),
            io_error: Some(e.message().unwrap_or_default()),
        },
    }
}
