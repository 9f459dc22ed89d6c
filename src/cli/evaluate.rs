//! `nurbsx evaluate`: parameters from `--at` and `--params`, evaluation by the pipeline.

use std::path::Path;

use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};

use crate::pipeline::{self, ErrorKind, EvalRequest, PipelineError};

use super::args::{EvaluateArgs, parse_tuple};
use super::{
    CliError, Context, Outcome, display_name, load_file, outcome_of, output, print_stdout,
    read_input, reader_error,
};

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
    let name = display_name(&a.input);
    let loaded = load_file(ctx, &a.input)?;
    let diagnostics = &loaded.document.diagnostics;
    let request = EvalRequest {
        entity: a.entity.clone(),
        params,
        derivatives: a.derivatives,
        normals: a.normals,
        curvature: a.curvature,
    };
    let report = match pipeline::evaluate(&loaded.document, &request, &ctx.settings) {
        Ok(report) => report,
        // The entity is missing because the reader refused it (a limit, invalid data): say
        // that, not "no such entity".
        Err(e) if e.code() == "entity.not_found" => {
            let error = reader_error(&loaded.document, a.entity.as_deref()).unwrap_or(e);
            if !a.json {
                let others: Vec<_> = diagnostics
                    .iter()
                    .filter(|d| **d != error.diagnostic)
                    .cloned()
                    .collect();
                ctx.report.diagnostics(&name, &others);
            }
            return Err(CliError::pipeline(&a.input, error));
        }
        Err(e) => {
            if !a.json {
                ctx.report.diagnostics(&name, diagnostics);
            }
            return Err(CliError::pipeline(&a.input, e));
        }
    };
    let text = if a.json {
        let mut value = serde_json::to_value(&report)
            .map_err(|e| CliError::Usage(format!("cannot serialise the results: {e}")))?;
        value["diagnostics"] = serde_json::json!(ctx.report.filter(diagnostics));
        let mut s = serde_json::to_string_pretty(&value)
            .map_err(|e| CliError::Usage(format!("cannot serialise the results: {e}")))?;
        s.push('\n');
        s
    } else {
        ctx.report.diagnostics(&name, diagnostics);
        output::eval_text(&report)
    };
    print_stdout(&text)?;
    Ok(outcome_of(diagnostics))
}

/// Reads a parameter file: a JSON array of arrays (when it starts with `[`), else one tuple
/// per line (`u`, `u,v` or `u v`), blank lines and `#` comments skipped. At most
/// `max_eval_points` tuples are read, so a huge file fails early instead of filling memory.
fn read_params(path: &Path, ctx: &Context) -> Result<Vec<Vec<f64>>, CliError> {
    let (bytes, _) = read_input(path, &ctx.settings)?;
    let name = display_name(path);
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| CliError::Usage(format!("{name}: not UTF-8 text: {e}")))?;
    let max = ctx.settings.max_eval_points;
    parse_params(text, max).map_err(|e| match e {
        ParamError::Syntax(m) => CliError::Usage(format!("{name}:{m}")),
        ParamError::TooMany => CliError::pipeline(
            path,
            PipelineError::new(
                ErrorKind::Limit,
                "limit.eval_points",
                format!("more than {max} parameters requested, above the limit"),
                Default::default(),
            ),
        ),
    })
}

/// Why a parameter file was refused.
#[derive(Debug, PartialEq)]
enum ParamError {
    /// Bad text; the message starts with the line (`3: ...`, `1:7: ...` for JSON).
    Syntax(String),
    /// More tuples than the limit.
    TooMany,
}

/// Parses parameter text, reading at most `max` tuples.
fn parse_params(text: &str, max: usize) -> Result<Vec<Vec<f64>>, ParamError> {
    if text.trim_start().starts_with('[') {
        let mut de = serde_json::Deserializer::from_str(text);
        let tuples = CappedTuples { max }
            .deserialize(&mut de)
            .and_then(|t| de.end().map(|()| t))
            .map_err(|e| {
                if e.to_string().starts_with(TOO_MANY) {
                    ParamError::TooMany
                } else {
                    ParamError::Syntax(format!(
                        "{}:{}: expected [[u], [u, v], ...]: {e}",
                        e.line(),
                        e.column()
                    ))
                }
            })?;
        return Ok(tuples);
    }
    let mut tuples = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        if tuples.len() == max {
            return Err(ParamError::TooMany);
        }
        tuples
            .push(parse_tuple(content).map_err(|m| ParamError::Syntax(format!("{}: {m}", i + 1)))?);
    }
    Ok(tuples)
}

const TOO_MANY: &str = "too many parameters";

/// A JSON array of at most `max` tuples of one or two finite numbers, read without ever
/// holding more than that (an inner array stops at its third element).
struct CappedTuples {
    max: usize,
}

impl<'de> DeserializeSeed<'de> for CappedTuples {
    type Value = Vec<Vec<f64>>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for CappedTuples {
    type Value = Vec<Vec<f64>>;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("an array of [u] or [u, v] arrays")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(t) = seq.next_element_seed(Tuple)? {
            if out.len() == self.max {
                return Err(de::Error::custom(TOO_MANY));
            }
            out.push(t);
        }
        Ok(out)
    }
}

/// One `[u]` or `[u, v]` of finite numbers.
struct Tuple;

impl<'de> DeserializeSeed<'de> for Tuple {
    type Value = Vec<f64>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for Tuple {
    type Value = Vec<f64>;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("[u] or [u, v]")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut t = Vec::with_capacity(2);
        while let Some(x) = seq.next_element::<f64>()? {
            if t.len() == 2 {
                return Err(de::Error::custom(
                    "expected [u] or [u, v], got a third number",
                ));
            }
            if !x.is_finite() {
                return Err(de::Error::custom("parameters must be finite"));
            }
            t.push(x);
        }
        if t.is_empty() {
            return Err(de::Error::custom("empty parameter tuple"));
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::{ParamError, parse_params};

    #[test]
    fn parameter_files_parse_in_both_forms() {
        assert_eq!(
            parse_params("# u v\n0.1, 0.2\n\n0.3 0.4\n", 10).unwrap(),
            vec![vec![0.1, 0.2], vec![0.3, 0.4]]
        );
        assert_eq!(
            parse_params(" [[0.5], [0.25]]", 10).unwrap(),
            vec![vec![0.5], vec![0.25]]
        );
        match parse_params("0.1\nx\n", 10) {
            Err(ParamError::Syntax(m)) => assert!(m.starts_with("2: "), "{m}"),
            other => panic!("{other:?}"),
        }
        for bad in ["[[1,2,3]]", "[[]]", "[[1]] x", "[1]", "[[1e999]]"] {
            assert!(
                matches!(parse_params(bad, 10), Err(ParamError::Syntax(_))),
                "{bad}"
            );
        }
    }

    #[test]
    fn parameter_files_stop_at_the_limit() {
        assert_eq!(parse_params("1\n2\n3\n", 2), Err(ParamError::TooMany));
        assert_eq!(parse_params("[[1],[2],[3]]", 2), Err(ParamError::TooMany));
        assert_eq!(parse_params("[[1],[2]]", 2).unwrap().len(), 2);
    }
}
