//! `nurbsx info` and `nurbsx validate`.

use rayon::prelude::*;

use crate::pipeline::{self, ValidationReport};

use super::args::{InfoArgs, ValidateArgs, ValidateFormat};
use super::output::{self, FileValidation};
use super::{CliError, Context, Outcome, display_name, eprint_line, print_stdout, read_input};

/// `nurbsx info FILE [--json]`: the pipeline's [`InfoReport`](crate::pipeline::InfoReport)
/// as a table or as JSON.
pub fn info(ctx: &Context, a: InfoArgs) -> Result<Outcome, CliError> {
    let name = display_name(&a.input);
    let (bytes, hint) = read_input(&a.input, &ctx.settings)?;
    let loaded =
        pipeline::load(&bytes, hint, &ctx.settings).map_err(|e| CliError::pipeline(&a.input, e))?;
    let report = pipeline::info(&loaded);
    let text = if a.json {
        let mut s = serde_json::to_string_pretty(&report).map_err(|e| {
            CliError::Usage(format!("cannot serialise the report of `{name}`: {e}"))
        })?;
        s.push('\n');
        s
    } else {
        output::info_text(&name, &report)
    };
    print_stdout(&text)?;
    Ok(Outcome::Success)
}

/// `nurbsx validate FILE...`: validates every file (a file that cannot be opened is reported
/// in the output and makes the exit code 2), then prints in the chosen format.
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
            paths.extend(super::batch::walk(input, None)?);
        } else {
            paths.push(input.clone());
        }
    }
    // Run: files are independent, so they are checked in parallel (order kept).
    let files: Vec<FileValidation> = paths
        .par_iter()
        .map(|path| check_one(ctx, path, a.strict))
        .collect();
    let io_failed = files.iter().any(|f| f.io_error.is_some());
    let text = match format {
        ValidateFormat::Text => output::validate_text(&files),
        ValidateFormat::Json => output::validate_json(&files),
        ValidateFormat::Junit => output::validate_junit(&files),
        ValidateFormat::Sarif => output::validate_sarif(&files),
    };
    print_stdout(&text)?;
    if io_failed {
        // Exit 2 without a second message: the output already names the file.
        return Err(CliError::Quiet(2));
    }
    if files.iter().all(|f| f.report.valid) {
        Ok(Outcome::Success)
    } else {
        Ok(Outcome::Failure)
    }
}

/// Validates one file; an I/O failure is recorded in the result (and printed on stderr).
fn check_one(ctx: &Context, path: &std::path::Path, strict: bool) -> FileValidation {
    let file = display_name(path);
    match read_input(path, &ctx.settings) {
        Ok((bytes, hint)) => FileValidation {
            file,
            report: pipeline::validate(&bytes, hint, strict, &ctx.settings),
            io_error: None,
        },
        // A limit refusal is a finding about the file, not an I/O failure.
        Err(CliError::Pipeline { error, .. }) => FileValidation {
            file,
            report: ValidationReport::new(0, vec![error.diagnostic], strict),
            io_error: None,
        },
        Err(e) => {
            let line = e.message().unwrap_or_default();
            eprint_line(&line);
            FileValidation {
                file,
                report: ValidationReport::new(0, Vec::new(), strict),
                io_error: Some(line.trim_start_matches("error: ").to_owned()),
            }
        }
    }
}
