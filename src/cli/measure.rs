//! `nurbsx measure` and `nurbsx compare`: load, measure or compare in the pipeline, print.

use crate::exchange::{Diagnostic, Location};
use crate::pipeline::measure::{
    CompareReport, MeasureReport, MeasureRequest, compare_summary, settings_for_second,
};

use super::args::{CompareArgs, MeasureArgs};
use super::{CliError, Context, Outcome, display_name, load_file, outcome_of, print_stdout};

/// `nurbsx measure`.
pub fn measure(ctx: &Context, a: MeasureArgs) -> Result<Outcome, CliError> {
    let closest = match a.closest.as_ref().map(|l| l.0.as_slice()) {
        None => None,
        Some(&[x, y]) => Some([x, y, 0.0]),
        Some(&[x, y, z]) => Some([x, y, z]),
        Some(other) => {
            return Err(CliError::Usage(format!(
                "--closest takes X,Y or X,Y,Z, got {} numbers",
                other.len()
            )));
        }
    };
    let name = display_name(&a.input);
    let loaded = load_file(ctx, &a.input)?;
    let diagnostics = &loaded.document.diagnostics;
    let request = MeasureRequest {
        entity: a.entity.clone(),
        closest,
        tolerance: a.tolerance,
    };
    let report = crate::pipeline::measure::measure(&loaded.document, &request, &ctx.settings)
        .map_err(|e| CliError::pipeline(&a.input, e))?;
    let warnings: Vec<Diagnostic> = report
        .entities
        .iter()
        .flat_map(|m| {
            let quantities = [("length", m.length), ("area", m.area)];
            quantities.into_iter().filter_map(move |(what, q)| {
                q.filter(|q| !q.converged).map(|q| {
                    Diagnostic::warning(
                        "measure.not_converged",
                        format!(
                            "the {what} of {} is {} with an error estimate of {:e}, above the \
                             tolerance {:e} ({} pieces, the limit)",
                            m.id, q.value, q.error_estimate, a.tolerance, q.pieces
                        ),
                        Location::at_entity(m.id.clone()),
                    )
                })
            })
        })
        .collect();
    let text = if a.json {
        let mut value = serde_json::to_value(&report)
            .map_err(|e| CliError::Usage(format!("cannot serialise the report: {e}")))?;
        let mut shown = ctx.report.filter(diagnostics);
        shown.extend(ctx.report.filter(&warnings));
        value["diagnostics"] = serde_json::json!(shown);
        let mut s = serde_json::to_string_pretty(&value)
            .map_err(|e| CliError::Usage(format!("cannot serialise the report: {e}")))?;
        s.push('\n');
        s
    } else {
        ctx.report.diagnostics(&name, diagnostics);
        ctx.report.diagnostics(&name, &warnings);
        measure_text(&report)
    };
    print_stdout(&text)?;
    if report.converged {
        Ok(outcome_of(diagnostics))
    } else {
        Ok(Outcome::Failure)
    }
}

fn measure_text(r: &MeasureReport) -> String {
    let mut out = String::new();
    for m in &r.entities {
        let mut line = format!("{} {}", m.kind, m.id);
        for (what, q) in [("length", m.length), ("area", m.area)] {
            if let Some(q) = q {
                line.push_str(&format!(
                    "  {what} {} (error estimate {:.1e}{})",
                    q.value,
                    q.error_estimate,
                    if q.converged { "" } else { ", NOT converged" }
                ));
            }
        }
        if let Some(c) = &m.closest {
            line.push_str(&format!(
                "  closest {:?} at {:?}, distance {}",
                c.point, c.parameters, c.distance
            ));
        }
        out.push_str(&line);
        out.push('\n');
    }
    if let Some(id) = &r.nearest {
        out.push_str(&format!("nearest entity: {id}\n"));
    }
    out
}

/// `nurbsx compare`.
pub fn compare(ctx: &Context, a: CompareArgs) -> Result<Outcome, CliError> {
    let first = load_file(ctx, &a.first)?;
    let second_ctx = Context {
        settings: settings_for_second(&ctx.settings, &first.document),
        ..ctx.clone()
    };
    let second = load_file(&second_ctx, &a.second)?;
    let (na, nb) = (display_name(&a.first), display_name(&a.second));
    let mut shown = ctx.report.filter(&first.document.diagnostics);
    shown.extend(ctx.report.filter(&second.document.diagnostics));
    let summary = compare_summary(
        &first.document,
        &second.document,
        a.tolerance,
        shown,
        &ctx.settings,
    )
    .map_err(|e| CliError::pipeline(&a.first, e))?;
    let text = if a.json {
        let mut s = serde_json::to_string_pretty(&summary)
            .map_err(|e| CliError::Usage(format!("cannot serialise the report: {e}")))?;
        s.push('\n');
        s
    } else {
        ctx.report.diagnostics(&na, &first.document.diagnostics);
        ctx.report.diagnostics(&nb, &second.document.diagnostics);
        compare_text(&summary.report, summary.units, a.tolerance)
    };
    print_stdout(&text)?;
    let read = outcome_of(&first.document.diagnostics) == Outcome::Success
        && outcome_of(&second.document.diagnostics) == Outcome::Success;
    Ok(if read && summary.within_tolerance != Some(false) {
        Outcome::Success
    } else {
        Outcome::Failure
    })
}

fn compare_text(r: &CompareReport, unit: &str, tolerance: Option<f64>) -> String {
    let mut out = format!(
        "Hausdorff distance {} {unit} ({} / {} curves, {} / {} surfaces)",
        r.distance, r.curves[0], r.curves[1], r.surfaces[0], r.surfaces[1]
    );
    if let Some(t) = tolerance {
        out.push_str(if r.distance <= t { " within" } else { " ABOVE" });
        out.push_str(&format!(" the tolerance {t}"));
    }
    out.push('\n');
    for (side, f) in [
        ("first -> second", &r.first_to_second),
        ("second -> first", &r.second_to_first),
    ] {
        if let Some(f) = f {
            out.push_str(&format!(
                "  {side}: {} from {} at {:?} ({:?}) to {} at {:?}\n",
                f.distance, f.entity, f.parameters, f.point, f.nearest_entity, f.nearest_parameters
            ));
        }
    }
    out
}
