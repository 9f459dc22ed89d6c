//! `nurbsx elevate`, `clamp`, `unclamp`, `insert-knot` and `tessellate`: read, apply one
//! pipeline operation, write in the input's form unless told otherwise.

use std::path::Path;

use crate::exchange::ExportOptions;
use crate::pipeline::{self, InputKind, Loaded, MeshFormat, Operation};

use super::args::{
    ElevateArgs, InsertKnotArgs, MeshFormatArg, ModelFormatArg, OutputArgs, SimpleOpArgs,
    TessellateArgs,
};
use super::{CliError, Context, Outcome, display_name, is_dash, read_input, write_output};

/// `nurbsx elevate`.
pub fn elevate(ctx: &Context, a: ElevateArgs) -> Result<Outcome, CliError> {
    if a.by == 0 {
        return Err(CliError::Usage("--by must be at least 1".into()));
    }
    let op = Operation::Elevate {
        by: a.by,
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx clamp` (`clamp = true`) and `nurbsx unclamp`.
pub fn clamp(ctx: &Context, a: SimpleOpArgs, clamp: bool) -> Result<Outcome, CliError> {
    let direction = a.direction.into();
    let op = if clamp {
        Operation::Clamp { direction }
    } else {
        Operation::Unclamp { direction }
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx insert-knot`.
pub fn insert_knot(ctx: &Context, a: InsertKnotArgs) -> Result<Outcome, CliError> {
    if a.times == 0 {
        return Err(CliError::Usage("--times must be at least 1".into()));
    }
    let op = Operation::InsertKnot {
        u: a.at,
        times: a.times,
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// The output form of a modify command: `--to`, else OUT's extension, else the input's.
fn output_kind(out: &OutputArgs, input: InputKind) -> Result<InputKind, CliError> {
    if let Some(to) = out.to {
        return Ok(match to {
            ModelFormatArg::Step => InputKind::Step,
            ModelFormatArg::Iges => InputKind::Iges,
            ModelFormatArg::Json => InputKind::Json,
        });
    }
    if is_dash(&out.output) || out.output.extension().is_none() {
        return Ok(input);
    }
    InputKind::from_path(&out.output).ok_or_else(|| {
        CliError::Usage(format!(
            "cannot tell the output format from `{}`: use .step/.stp/.p21, .igs/.iges or \
             .json, or give --to step|iges|json",
            out.output.display()
        ))
    })
}

/// Loads, applies `op` to one entity or all, and writes.
fn modify(
    ctx: &Context,
    input: &Path,
    out: &OutputArgs,
    op: Operation,
    entity: Option<&str>,
) -> Result<Outcome, CliError> {
    let Loaded { kind, mut document } = load(ctx, input)?;
    let target = output_kind(out, kind)?;
    tracing::info!(?op, input = %input.display(), output = %out.output.display(), "modify");
    pipeline::apply(&mut document, op, entity, &ctx.settings)
        .map_err(|e| CliError::pipeline(input, e))?;
    let text = pipeline::write_as(&document, target, &export_options(&out.output))
        .map_err(|e| CliError::pipeline(&out.output, e))?;
    write_output(&out.output, &text)?;
    Ok(Outcome::Success)
}

/// Reads and loads an input, printing the reader's diagnostics.
fn load(ctx: &Context, input: &Path) -> Result<Loaded, CliError> {
    let (bytes, hint) = read_input(input, &ctx.settings)?;
    let loaded =
        pipeline::load(&bytes, hint, &ctx.settings).map_err(|e| CliError::pipeline(input, e))?;
    ctx.print_diagnostics(&display_name(input), &loaded.document.diagnostics);
    Ok(loaded)
}

/// Writer options naming the output file in the header.
fn export_options(output: &Path) -> ExportOptions {
    let mut options = ExportOptions::default();
    if let Some(name) = output.file_name().and_then(|n| n.to_str()) {
        options.file_name = name.to_owned();
    }
    options
}

/// `nurbsx tessellate`.
pub fn tessellate(ctx: &Context, a: TessellateArgs) -> Result<Outcome, CliError> {
    let format = match a.format {
        Some(MeshFormatArg::Obj) => MeshFormat::Obj,
        Some(MeshFormatArg::Svg) => MeshFormat::Svg,
        None => {
            let ext = a
                .output
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            match ext.as_deref() {
                Some("obj") => MeshFormat::Obj,
                Some("svg") => MeshFormat::Svg,
                _ => {
                    return Err(CliError::Usage(format!(
                        "cannot tell the mesh format from `{}`: use .obj or .svg, or give \
                         --format obj|svg",
                        a.output.display()
                    )));
                }
            }
        }
    };
    let loaded = load(ctx, &a.input)?;
    let text = pipeline::tessellate(
        &loaded.document,
        a.entity.as_deref(),
        a.tolerance,
        format,
        &ctx.settings,
    )
    .map_err(|e| CliError::pipeline(&a.input, e))?;
    write_output(&a.output, &text)?;
    Ok(Outcome::Success)
}
