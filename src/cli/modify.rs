//! `nurbsx elevate`, `clamp`, `unclamp`, `insert-knot`, `refine`, `reduce`, `remove-knots`,
//! `decompose`, `split`, `join`, `reverse`, `reparameterize`, `transform`, `iso`,
//! `periodic`, `derivative-curve` and `tessellate`: read, apply one pipeline operation,
//! write in the input's form unless told otherwise.

use std::path::Path;

use crate::exchange::ExportOptions;
use crate::pipeline::{self, InputKind, Loaded, MeshFormat, Operation};

use super::args::{
    DerivativeCurveArgs, ElevateArgs, EntityOpArgs, FitArgs, InsertKnotArgs, IsoArgs, JoinArgs,
    MakeArgs, MakeKind, MeshFormatArg, ModelFormatArg, NumberList, OutputArgs, ParamsArg,
    PeriodicArgs, ReduceArgs, RefineArgs, ReparameterizeArgs, SimpleOpArgs, SplitArgs,
    TessellateArgs, ToleranceOpArgs, TransformArgs,
};
use super::inspect::no_bspline_warning;
use super::{
    CliError, Context, Outcome, display_name, is_dash, load_file, outcome_of, reader_error,
    write_bytes, write_output,
};
use crate::pipeline::Direction;

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

/// `nurbsx refine`.
pub fn refine(ctx: &Context, a: RefineArgs) -> Result<Outcome, CliError> {
    let op = match a.knots {
        Some(knots) if !a.halve => Operation::Refine {
            knots: knots.0,
            direction: a.direction.into(),
        },
        _ => Operation::Halve {
            direction: a.direction.into(),
        },
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx reduce`.
pub fn reduce(ctx: &Context, a: ReduceArgs) -> Result<Outcome, CliError> {
    let op = Operation::Reduce {
        tolerance: a.tolerance,
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx remove-knots`.
pub fn remove_knots(ctx: &Context, a: ToleranceOpArgs) -> Result<Outcome, CliError> {
    let op = Operation::RemoveKnots {
        tolerance: a.tolerance,
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx decompose`.
pub fn decompose(ctx: &Context, a: EntityOpArgs) -> Result<Outcome, CliError> {
    modify(
        ctx,
        &a.input,
        &a.out,
        Operation::Decompose,
        a.entity.as_deref(),
    )
}

/// `nurbsx split`.
pub fn split(ctx: &Context, a: SplitArgs) -> Result<Outcome, CliError> {
    let op = Operation::Split {
        at: a.at,
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx join`.
pub fn join(ctx: &Context, a: JoinArgs) -> Result<Outcome, CliError> {
    let op = Operation::Join {
        tolerance: a.tolerance,
    };
    modify(ctx, &a.input, &a.out, op, None)
}

/// `nurbsx reverse`.
pub fn reverse(ctx: &Context, a: SimpleOpArgs) -> Result<Outcome, CliError> {
    let op = Operation::Reverse {
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx reparameterize`.
pub fn reparameterize(ctx: &Context, a: ReparameterizeArgs) -> Result<Outcome, CliError> {
    let [start, end] = a.to.0[..] else {
        return Err(CliError::Usage(format!(
            "--to takes two numbers A,B, got {}",
            a.to.0.len()
        )));
    };
    let op = Operation::Reparameterize {
        start,
        end,
        direction: a.direction.into(),
    };
    let out = OutputArgs {
        output: a.output,
        to: None,
        knot_intervals: a.knot_intervals,
    };
    modify(ctx, &a.input, &out, op, a.entity.as_deref())
}

/// `nurbsx transform`.
pub fn transform(ctx: &Context, a: TransformArgs) -> Result<Outcome, CliError> {
    let matrix = match &a.matrix {
        Some(m) => {
            let [r11, r12, r13, t1, r21, r22, r23, t2, r31, r32, r33, t3] = m.0[..] else {
                return Err(CliError::Usage(format!(
                    "--matrix takes 12 numbers (the rows of [R | T]), got {}",
                    m.0.len()
                )));
            };
            [
                [r11, r12, r13, t1],
                [r21, r22, r23, t2],
                [r31, r32, r33, t3],
            ]
        }
        None => {
            let rotate = match a.rotate.as_ref().map(|r| &r.0[..]) {
                None => None,
                Some(&[x, y, z, deg]) => Some(([x, y, z], deg)),
                Some(other) => {
                    return Err(CliError::Usage(format!(
                        "--rotate takes 4 numbers AX,AY,AZ,DEGREES, got {}",
                        other.len()
                    )));
                }
            };
            let translate = match a.translate.as_ref().map(|t| &t.0[..]) {
                None => None,
                Some(&[x, y, z]) => Some([x, y, z]),
                Some(other) => {
                    return Err(CliError::Usage(format!(
                        "--translate takes 3 numbers X,Y,Z, got {}",
                        other.len()
                    )));
                }
            };
            if a.scale.is_none() && rotate.is_none() && translate.is_none() {
                return Err(CliError::Usage(
                    "give --matrix, or at least one of --scale, --rotate, --translate".into(),
                ));
            }
            pipeline::affine(a.scale, rotate, translate)
                .map_err(|e| CliError::pipeline(&a.input, e))?
        }
    };
    modify(
        ctx,
        &a.input,
        &a.out,
        Operation::Transform { matrix },
        a.entity.as_deref(),
    )
}

/// `nurbsx iso`.
pub fn iso(ctx: &Context, a: IsoArgs) -> Result<Outcome, CliError> {
    let op = match (a.u, a.v) {
        (Some(at), None) => Operation::Iso {
            at,
            direction: Direction::U,
        },
        (None, Some(at)) => Operation::Iso {
            at,
            direction: Direction::V,
        },
        _ => return Err(CliError::Usage("give exactly one of --u and --v".into())),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx periodic`.
pub fn periodic(ctx: &Context, a: PeriodicArgs) -> Result<Outcome, CliError> {
    let op = Operation::Periodic {
        tolerance: a.tolerance,
        direction: a.direction.into(),
    };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// `nurbsx derivative-curve`.
pub fn derivative_curve(ctx: &Context, a: DerivativeCurveArgs) -> Result<Outcome, CliError> {
    let op = Operation::DerivativeCurve { order: a.order };
    modify(ctx, &a.input, &a.out, op, a.entity.as_deref())
}

/// A point or vector option: 3 numbers, or the default.
fn point(
    v: &Option<NumberList>,
    name: &str,
    default: Option<[f64; 3]>,
) -> Result<[f64; 3], CliError> {
    match (v.as_ref().map(|l| &l.0[..]), default) {
        (Some(&[x, y, z]), _) => Ok([x, y, z]),
        (Some(other), _) => Err(CliError::Usage(format!(
            "--{name} takes 3 numbers X,Y,Z, got {}",
            other.len()
        ))),
        (None, Some(d)) => Ok(d),
        (None, None) => Err(CliError::Usage(format!("this shape needs --{name} X,Y,Z"))),
    }
}

/// The first curve of a file.
fn curve_file(ctx: &Context, path: &Path) -> Result<crate::nurbs::NurbsCurve, CliError> {
    let Loaded { document, .. } = load_file(ctx, path)?;
    ctx.report
        .diagnostics(&display_name(path), &document.diagnostics);
    document
        .entities
        .into_iter()
        .find_map(|e| match e.geometry {
            crate::nurbs::Geometry::Curve(c) => Some(c),
            crate::nurbs::Geometry::Surface(_) => None,
        })
        .ok_or_else(|| CliError::Usage(format!("{} holds no curve", path.display())))
}

/// `nurbsx make`.
pub fn make(ctx: &Context, a: MakeArgs) -> Result<Outcome, CliError> {
    use crate::pipeline::construct::{self, MakeSpec, make};
    let optional = |v: &Option<NumberList>, name: &str| -> Result<Option<[f64; 3]>, CliError> {
        match v {
            None => Ok(None),
            some => point(some, name, None).map(Some),
        }
    };
    let kind = match a.shape {
        MakeKind::Circle => construct::MakeKind::Circle,
        MakeKind::Arc => construct::MakeKind::Arc,
        MakeKind::Ellipse => construct::MakeKind::Ellipse,
        MakeKind::Line => construct::MakeKind::Line,
        MakeKind::Cylinder => construct::MakeKind::Cylinder,
        MakeKind::Cone => construct::MakeKind::Cone,
        MakeKind::Sphere => construct::MakeKind::Sphere,
        MakeKind::Torus => construct::MakeKind::Torus,
        MakeKind::Revolve => construct::MakeKind::Revolve,
        MakeKind::Extrude => construct::MakeKind::Extrude,
        MakeKind::Ruled => construct::MakeKind::Ruled,
        MakeKind::Coons => construct::MakeKind::Coons,
    };
    let spec = MakeSpec {
        centre: optional(&a.centre, "centre")?,
        axis: optional(&a.axis, "axis")?,
        reference: optional(&a.reference, "reference")?,
        radius: a.radius,
        start: Some(a.start),
        end: Some(a.end),
        major: a.major,
        minor: a.minor,
        p0: optional(&a.p0, "p0")?,
        p1: optional(&a.p1, "p1")?,
        height: a.height,
        semi_angle: a.semi_angle,
        sweep: Some(if kind == construct::MakeKind::Revolve {
            a.angle
        } else {
            a.sweep
        }),
        axis_point: optional(&a.axis_point, "axis-point")?,
        direction: optional(&a.direction, "direction")?,
        tolerance: Some(a.tolerance),
        curves: a
            .curves
            .iter()
            .map(|path| curve_file(ctx, path))
            .collect::<Result<_, _>>()?,
    };
    let shape =
        construct::shape(kind, spec).map_err(|e| CliError::pipeline(Path::new("make"), e))?;
    let mut document = make(&shape).map_err(|e| CliError::pipeline(Path::new("make"), e))?;
    let target = output_kind(&a.out, InputKind::Json)?;
    write_built(ctx, "make", &mut document, &a.out, target)?;
    let name = clap::ValueEnum::to_possible_value(&a.shape)
        .map_or_else(String::new, |v| v.get_name().to_owned());
    ctx.report.summary(&format!(
        "made a {name} -> {} as {}",
        display_name(&a.out.output),
        target.name().to_ascii_uppercase()
    ));
    Ok(outcome_of(&document.diagnostics))
}

/// `nurbsx fit`.
pub fn fit(ctx: &Context, a: FitArgs) -> Result<Outcome, CliError> {
    use crate::nurbs::fit::ParamMethod;
    use crate::pipeline::construct::{FitSpec, fit, read_fit_data};
    let (bytes, _) = super::read_input(&a.input, &ctx.settings)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| CliError::Usage(format!("{} is not UTF-8 text", a.input.display())))?;
    let (data, dimension) = read_fit_data(&text).map_err(|e| CliError::pipeline(&a.input, e))?;
    let method = match a.params {
        ParamsArg::Uniform => ParamMethod::Uniform,
        ParamsArg::Chord => ParamMethod::ChordLength,
        ParamsArg::Centripetal => ParamMethod::Centripetal,
    };
    let spec = FitSpec {
        degree: a.degree,
        degree_v: a.degree_v,
        poles: a.poles,
        poles_v: a.poles_v,
        method,
    };
    let (mut document, report) =
        fit(&data, dimension, spec).map_err(|e| CliError::pipeline(&a.input, e))?;
    let target = output_kind(&a.out, InputKind::Json)?;
    write_built(ctx, &display_name(&a.input), &mut document, &a.out, target)?;
    let sizes = |v: &[usize]| {
        v.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(" x ")
    };
    ctx.report.summary(&format!(
        "{} -> {}: {} of {} points by a {} of degree {} with {} poles as {}; residual max \
         {:e}, rms {:e}",
        display_name(&a.input),
        display_name(&a.out.output),
        report.method.replace('_', "-"),
        sizes(&report.points),
        if report.points.len() == 1 {
            "curve"
        } else {
            "surface"
        },
        match a.degree_v {
            Some(q) if report.points.len() == 2 => format!("{} x {q}", a.degree),
            _ => a.degree.to_string(),
        },
        sizes(&report.poles),
        target.name().to_ascii_uppercase(),
        report.residual_max,
        report.residual_rms,
    ));
    Ok(outcome_of(&document.diagnostics))
}

/// Writes a document that `make` or `fit` built: what `target` cannot hold (a 2-D curve in
/// IGES, a declared range) is dropped and reported first, and every diagnostic, the
/// writer's included, is printed, also when writing fails. When nothing of it fits the
/// format, no file is written: a usage error names the formats that hold it.
fn write_built(
    ctx: &Context,
    name: &str,
    document: &mut crate::exchange::Document,
    out: &OutputArgs,
    target: InputKind,
) -> Result<(), CliError> {
    if let Some(format) = target.format() {
        let built = document.entities.len();
        pipeline::drop_unwritable(document, format);
        if built > 0 && document.entities.is_empty() {
            // Nothing of what was built fits the format: an empty file is no answer.
            ctx.report.diagnostics(name, &document.diagnostics);
            return Err(CliError::Usage(format!(
                "{} output cannot hold what {name} built (see the warning above): write it as \
                 --to step or --to json",
                target.name().to_ascii_uppercase()
            )));
        }
    }
    let result = write_document(document, out, target);
    ctx.report.diagnostics(name, &document.diagnostics);
    result
}

/// Writes `document` as `target` to `out`'s file (its name in the header, the knot form it
/// asks for); what the writer says about it joins the document's diagnostics. What the
/// format cannot hold must have been dropped first (`pipeline::drop_unwritable`).
fn write_document(
    document: &mut crate::exchange::Document,
    out: &OutputArgs,
    target: InputKind,
) -> Result<(), CliError> {
    let (text, written) = pipeline::write_as(
        document,
        target,
        &export_options(&out.output),
        knot_form(out, target)?,
    )
    .map_err(|e| CliError::pipeline(&out.output, e))?;
    document.diagnostics.extend(written);
    write_output(&out.output, &text)
}

/// How model JSON output writes curve knots (`--knot-intervals`, refused for files).
fn knot_form(out: &OutputArgs, target: InputKind) -> Result<pipeline::KnotForm, CliError> {
    match (out.knot_intervals, target.format()) {
        (false, _) => Ok(pipeline::KnotForm::Vector),
        (true, None) => Ok(pipeline::KnotForm::Intervals),
        (true, Some(_)) => Err(CliError::Usage(format!(
            "--knot-intervals is a model JSON form; {} output has knot vectors",
            target.name().to_ascii_uppercase()
        ))),
    }
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

/// Loads, applies `op` to one entity or all, and writes; the diagnostics include what the
/// output format cannot hold (left out with a warning), and a summary says what was written.
fn modify(
    ctx: &Context,
    input: &Path,
    out: &OutputArgs,
    op: Operation,
    entity: Option<&str>,
) -> Result<Outcome, CliError> {
    let name = display_name(input);
    let Loaded { kind, mut document } = load_file(ctx, input)?;
    let target = output_kind(out, kind)?;
    tracing::info!(?op, input = %input.display(), output = %out.output.display(), "modify");
    let read = document.entities.len();
    // What the output cannot hold is dropped once: before the operation for loose
    // geometry, after it when the operation first drops the faces (whose pcurves the output
    // could have carried), so that every warning is printed.
    let faces = !document.topology.is_empty();
    if let Some(format) = target.format().filter(|_| !faces) {
        pipeline::drop_unwritable(&mut document, format);
    }
    if let Some(outcome) = nothing_to_do(ctx, &name, input, &document, entity)? {
        return Ok(outcome);
    }
    let notes = pipeline::apply(&mut document, op, entity, &ctx.settings)
        .map_err(|e| CliError::pipeline(input, e))?;
    if let Some(format) = target.format().filter(|_| faces) {
        pipeline::drop_unwritable(&mut document, format);
    }
    // The writer's diagnostics are printed with the rest, also when writing fails.
    let result = write_document(&mut document, out, target);
    ctx.report.diagnostics(&name, &document.diagnostics);
    result?;
    let written = document.entities.len();
    let mut summary = format!(
        "{name} -> {}: read {read} curves and surfaces, wrote {written} as {}",
        display_name(&out.output),
        target.name().to_ascii_uppercase()
    );
    if read > written {
        summary.push_str(&format!(
            ", left out {} (2-D parameter-space curves: see the pcurve_not_written warning)",
            read - written
        ));
    }
    for note in &notes {
        summary.push_str(&format!("\n  {}: {}", note.entity, note.message));
    }
    ctx.report.summary(&summary);
    Ok(outcome_of(&document.diagnostics))
}

/// When the document holds no entity to work on: the reader's error that explains it (a
/// limit, invalid data; exit 1), else the `no_bspline` warning that `convert` and `validate`
/// give too (nothing written, exit 0). `None` when there is work to do.
fn nothing_to_do(
    ctx: &Context,
    name: &str,
    input: &Path,
    document: &crate::exchange::Document,
    entity: Option<&str>,
) -> Result<Option<Outcome>, CliError> {
    let missing = match entity {
        None => document.entities.is_empty(),
        Some(_) => pipeline::select(document, entity).is_err(),
    };
    if !missing {
        return Ok(None);
    }
    if let Some(error) = reader_error(document, entity) {
        let others: Vec<_> = document
            .diagnostics
            .iter()
            .filter(|d| **d != error.diagnostic)
            .cloned()
            .collect();
        ctx.report.diagnostics(name, &others);
        return Err(CliError::pipeline(input, error));
    }
    if entity.is_some() {
        // An id that is not in the file: the usage error that lists the ids there are.
        return pipeline::select(document, entity)
            .map(|_| None)
            .map_err(|e| CliError::pipeline(input, e));
    }
    ctx.report.diagnostics(name, &document.diagnostics);
    ctx.report
        .diagnostic(Some(name), &no_bspline_warning(document.diagnostics.len()));
    Ok(Some(Outcome::Success))
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
        Some(f) => f,
        None => {
            let ext = a
                .output
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            match ext.as_deref() {
                Some("obj") => MeshFormatArg::Obj,
                Some("stl") => MeshFormatArg::Stl,
                Some("glb") => MeshFormatArg::Glb,
                Some("svg") => MeshFormatArg::Svg,
                Some("png") => MeshFormatArg::Png,
                _ => {
                    return Err(CliError::Usage(format!(
                        "cannot tell the mesh format from `{}`: use .obj, .stl, .glb, .svg \
                         or .png, or give --format obj|stl|glb|svg|png",
                        a.output.display()
                    )));
                }
            }
        }
    };
    let format = match format {
        MeshFormatArg::Obj => MeshFormat::Obj,
        MeshFormatArg::Stl => MeshFormat::Stl,
        MeshFormatArg::Glb => MeshFormat::Glb,
        MeshFormatArg::Svg => MeshFormat::Svg,
        MeshFormatArg::Png => MeshFormat::Png,
    };
    let name = display_name(&a.input);
    let loaded = load_file(ctx, &a.input)?;
    if let Some(outcome) =
        nothing_to_do(ctx, &name, &a.input, &loaded.document, a.entity.as_deref())?
    {
        return Ok(outcome);
    }
    let plan = pipeline::mesh::plan(&loaded.document, a.entity.as_deref(), format)
        .map_err(|e| CliError::pipeline(&a.input, e))?;
    let mut diagnostics = loaded.document.diagnostics.clone();
    let drawn = plan.items();
    let (faces, edges) = (plan.faces.len(), plan.edges.len());
    diagnostics.extend(plan.left_out);
    ctx.report.diagnostics(&name, &diagnostics);
    let file = pipeline::tessellate_file(
        &loaded.document,
        a.entity.as_deref(),
        a.tolerance,
        format,
        &ctx.settings,
    )
    .map_err(|e| CliError::pipeline(&a.input, e))?;
    ctx.report.diagnostics(&name, &file.diagnostics);
    diagnostics.extend(file.diagnostics);
    write_bytes(&a.output, &file.bytes)?;
    ctx.report.summary(&format!(
        "{name} -> {}: drew {drawn} item(s): {faces} trimmed face(s), {edges} edge(s), {} \
         free curve(s) and surface(s)",
        display_name(&a.output),
        drawn - faces - edges,
    ));
    Ok(outcome_of(&diagnostics))
}
