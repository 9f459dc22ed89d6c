//! `nurbsx evaluate`: parameters from `--at` and `--params`, evaluation by the pipeline.

use std::path::Path;

use crate::pipeline::{self, EvalRequest};

use super::args::{EvaluateArgs, parse_tuple};
use super::{CliError, Context, Outcome, display_name, output, print_stdout, read_input};

/// Runs `nurbsx evaluate`.
pub fn run(ctx: &Context, a: EvaluateArgs) -> Result<Outcome, CliError> {
    // Plan: gather every parameter tuple before reading the geometry, so that a bad
    // parameter file fails fast.
    let mut params = a.at.clone();
    if let Some(file) = &a.params {
        params.extend(read_params(file, ctx)?);
    }
    if params.is_empty() {
        return Err(CliError::Usage(
            "give at least one parameter with --at U (curves), --at U,V (surfaces) or --params FILE"
                .into(),
        ));
    }
    if let Some(bad) = params.windows(2).find(|w| w[0].len() != w[1].len()) {
        return Err(CliError::Usage(format!(
            "mixed parameter tuples: {:?} and {:?} (curves take `u`, surfaces `u,v`)",
            bad[0], bad[1]
        )));
    }
    let (bytes, hint) = read_input(&a.input, &ctx.settings)?;
    let loaded =
        pipeline::load(&bytes, hint, &ctx.settings).map_err(|e| CliError::pipeline(&a.input, e))?;
    ctx.print_diagnostics(&display_name(&a.input), &loaded.document.diagnostics);
    let request = EvalRequest {
        entity: a.entity.clone(),
        params,
        derivatives: a.derivatives,
        normals: a.normals,
        curvature: a.curvature,
    };
    let report = pipeline::evaluate(&loaded.document, &request, &ctx.settings)
        .map_err(|e| CliError::pipeline(&a.input, e))?;
    let text = if a.json {
        let mut s = serde_json::to_string_pretty(&report)
            .map_err(|e| CliError::Usage(format!("cannot serialise the results: {e}")))?;
        s.push('\n');
        s
    } else {
        output::eval_text(&report)
    };
    print_stdout(&text)?;
    Ok(Outcome::Success)
}

/// Reads a parameter file: a JSON array of arrays (when it starts with `[`), else one tuple
/// per line (`u`, `u,v` or `u v`), blank lines and `#` comments skipped.
fn read_params(path: &Path, ctx: &Context) -> Result<Vec<Vec<f64>>, CliError> {
    let (bytes, _) = read_input(path, &ctx.settings)?;
    let name = display_name(path);
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| CliError::Usage(format!("{name}: not UTF-8 text: {e}")))?;
    parse_params(text).map_err(|m| CliError::Usage(format!("{name}:{m}")))
}

/// Parses parameter text; the error starts with the line number (`3: ...`).
fn parse_params(text: &str) -> Result<Vec<Vec<f64>>, String> {
    if text.trim_start().starts_with('[') {
        let tuples: Vec<Vec<f64>> = serde_json::from_str(text).map_err(|e| {
            format!(
                "{}:{}: expected [[u], [u, v], ...]: {e}",
                e.line(),
                e.column()
            )
        })?;
        for (i, t) in tuples.iter().enumerate() {
            if !(1..=2).contains(&t.len()) || t.iter().any(|x| !x.is_finite()) {
                return Err(format!(
                    " element {i}: expected [u] or [u, v] with finite numbers, got {t:?}"
                ));
            }
        }
        return Ok(tuples);
    }
    let mut tuples = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        tuples.push(parse_tuple(content).map_err(|m| format!("{}: {m}", i + 1))?);
    }
    Ok(tuples)
}

#[cfg(test)]
mod tests {
    use super::parse_params;

    #[test]
    fn parameter_files_parse_in_both_forms() {
        assert_eq!(
            parse_params("# u v\n0.1, 0.2\n\n0.3 0.4\n").unwrap(),
            vec![vec![0.1, 0.2], vec![0.3, 0.4]]
        );
        assert_eq!(
            parse_params(" [[0.5], [0.25]]").unwrap(),
            vec![vec![0.5], vec![0.25]]
        );
        let err = parse_params("0.1\nx\n").unwrap_err();
        assert!(err.starts_with("2: "), "{err}");
        assert!(parse_params("[[1,2,3]]").is_err());
    }
}
