//! Batch conversion: plan the (input, output) pairs from files and folders, convert them in
//! parallel (rayon) with a progress bar on a terminal, write one JSON line per file to the
//! report, print a summary. Any failed file makes the exit code 1.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use crate::pipeline::InputKind;

use crate::exchange::Diagnostic;

use super::args::CollisionArg;
use super::convert::{
    Converted, FileRecord, Plan, batch_output_path, convert_bytes, empty_record, failure_record,
    success_record,
};
use super::{CliError, Context, Outcome, display_name, outcome_of, write_output};

/// The batch options besides the conversion plan.
#[derive(Debug, Clone, Copy)]
pub struct Options<'a> {
    /// `--report FILE`.
    pub report: Option<&'a Path>,
    /// `-j N`.
    pub jobs: Option<usize>,
    /// `--on-collision`.
    pub on_collision: CollisionArg,
}

/// One planned conversion.
#[derive(Debug, Clone)]
struct Job {
    input: PathBuf,
    output: PathBuf,
}

/// Whether a file found in a folder is one to convert (by extension, case-insensitive).
fn is_exchange_file(path: &Path) -> bool {
    matches!(
        InputKind::from_path(path),
        Some(InputKind::Step | InputKind::Iges)
    )
}

/// Lists the exchange files under `root`, sorted, without following symbolic links to
/// folders (so a link cycle cannot loop) and without entering `skip` (the batch's own output
/// folder, so that a rerun does not convert its previous outputs). Iterative: folder depth
/// cannot exhaust the stack.
pub fn walk(ctx: &Context, root: &Path, skip: Option<&Path>) -> Result<Vec<PathBuf>, CliError> {
    let skip = skip.and_then(|p| p.canonicalize().ok());
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let io_err = |source| CliError::Io {
            context: format!("cannot list `{}`", dir.display()),
            source,
        };
        let listed = std::fs::read_dir(&dir).and_then(|d| d.collect::<Result<Vec<_>, _>>());
        let mut entries = match listed {
            Ok(entries) => entries,
            Err(e) if dir == root => return Err(io_err(e)),
            // One unreadable subfolder should not stop a batch over a large tree: say so and
            // go on (the summary counts only the files found).
            Err(e) => {
                ctx.report.diagnostic(
                    Some(&display_name(&dir)),
                    &Diagnostic::warning(
                        "io.skipped",
                        format!("folder skipped: {e}"),
                        Default::default(),
                    ),
                );
                continue;
            }
        };
        entries.sort_by_key(|e| e.file_name());
        for entry in entries {
            let path = entry.path();
            let file_type = entry.file_type().map_err(io_err)?;
            if file_type.is_dir() {
                if skip.is_none() || path.canonicalize().ok() != skip {
                    stack.push(path);
                }
            } else if (file_type.is_file() || file_type.is_symlink())
                && path.is_file()
                && is_exchange_file(&path)
            {
                found.push(path);
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Expands the inputs into jobs: files as given, folders searched recursively, each output
/// at the same relative place under `out_dir`. Outputs that would collide (`a.igs` and
/// `a.stp` both to `a.step`) are refused, numbered (`a-2.step`) or overwritten by the later
/// input, as `--on-collision` says; the last two with a warning naming both inputs.
fn plan_jobs(
    ctx: &Context,
    inputs: &[PathBuf],
    out_dir: &Path,
    plan: &Plan,
    on_collision: CollisionArg,
) -> Result<Vec<Job>, CliError> {
    let mut jobs: Vec<Job> = Vec::new();
    let mut taken: HashMap<PathBuf, usize> = HashMap::new();
    for input in inputs {
        let meta = std::fs::metadata(input).map_err(|source| CliError::Io {
            context: format!("cannot read `{}`", input.display()),
            source,
        })?;
        let pairs: Vec<(PathBuf, PathBuf)> = if meta.is_dir() {
            walk(ctx, input, Some(out_dir))?
                .into_iter()
                .map(|file| {
                    let relative = file.strip_prefix(input).unwrap_or(&file).to_path_buf();
                    (file, relative)
                })
                .collect()
        } else {
            let name = input.file_name().map(PathBuf::from).unwrap_or_default();
            vec![(input.clone(), name)]
        };
        for (file, relative) in pairs {
            let base = batch_output_path(out_dir, &relative, plan.request.to);
            let Some(&earlier) = taken.get(&base) else {
                taken.insert(base.clone(), jobs.len());
                jobs.push(Job {
                    input: file,
                    output: base,
                });
                continue;
            };
            let first = display_name(&jobs[earlier].input);
            let this = display_name(&file);
            let target = display_name(&base);
            match on_collision {
                CollisionArg::Error => {
                    return Err(CliError::Usage(format!(
                        "`{first}` and `{this}` would both be written to `{target}`; rename \
                         one, convert them separately, or give --on-collision rename|overwrite"
                    )));
                }
                CollisionArg::Overwrite => {
                    ctx.report.diagnostic(
                        Some(&first),
                        &Diagnostic::warning(
                            "batch.collision",
                            format!(
                                "not converted: `{this}` is written to `{target}` instead \
                                 (--on-collision overwrite)"
                            ),
                            Default::default(),
                        ),
                    );
                    jobs[earlier].input = file;
                }
                CollisionArg::Rename => {
                    // Number the later ones `a-2.step`, `a-3.step`, ...
                    let mut n = 2usize;
                    let output = loop {
                        let stem = base.file_stem().unwrap_or_default().to_string_lossy();
                        let name = match base.extension() {
                            Some(ext) => format!("{stem}-{n}.{}", ext.to_string_lossy()),
                            None => format!("{stem}-{n}"),
                        };
                        let candidate = base.with_file_name(name);
                        if !taken.contains_key(&candidate) {
                            break candidate;
                        }
                        n += 1;
                    };
                    ctx.report.diagnostic(
                        Some(&this),
                        &Diagnostic::warning(
                            "batch.collision",
                            format!(
                                "written to `{}` because `{first}` is written to `{target}` \
                                 (--on-collision rename)",
                                display_name(&output)
                            ),
                            Default::default(),
                        ),
                    );
                    taken.insert(output.clone(), jobs.len());
                    jobs.push(Job {
                        input: file,
                        output,
                    });
                }
            }
        }
    }
    Ok(jobs)
}

/// Whether writing `output` would replace `input` (same file).
fn same_file(input: &Path, output: &Path) -> bool {
    match (input.canonicalize(), output.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Converts one job; never fails, the record says what happened.
fn convert_one(job: &Job, plan: &Plan) -> (FileRecord, Vec<crate::exchange::Diagnostic>) {
    let name = display_name(&job.input);
    if same_file(&job.input, &job.output) {
        let d = crate::exchange::Diagnostic::error(
            "batch.overwrite",
            format!(
                "the output `{}` is the input itself; choose another --out-dir or --to",
                job.output.display()
            ),
            Default::default(),
        );
        return (failure_record(&name, d, None), Vec::new());
    }
    let (bytes, hint) = match super::read_input(&job.input, &plan.settings) {
        Ok(x) => x,
        Err(e) => {
            let d = match e {
                CliError::Pipeline { error, .. } => error.diagnostic,
                other => crate::exchange::Diagnostic::error(
                    "io",
                    other.message().unwrap_or_default(),
                    Default::default(),
                ),
            };
            return (failure_record(&name, d, None), Vec::new());
        }
    };
    let mut plan = plan.clone();
    if let Some(file_name) = job.output.file_name().and_then(|n| n.to_str()) {
        plan.request.export.file_name = file_name.to_owned();
    }
    match convert_bytes(&job.input, &bytes, hint, &plan) {
        Err(e) => (failure_record(&name, e.diagnostic, hint), Vec::new()),
        Ok(Converted::Empty(diagnostics)) => (empty_record(&name, hint, &diagnostics), diagnostics),
        Ok(Converted::Written(out)) => match write_output(&job.output, &out.text) {
            Ok(()) => {
                let record = success_record(&name, Some(display_name(&job.output)), &out.report);
                (record, out.report.diagnostics)
            }
            Err(e) => {
                let d = crate::exchange::Diagnostic::error(
                    "io",
                    e.message().unwrap_or_default(),
                    Default::default(),
                );
                (failure_record(&name, d, hint), Vec::new())
            }
        },
    }
}

/// Runs a batch conversion.
pub fn run(
    ctx: &Context,
    inputs: &[PathBuf],
    out_dir: &Path,
    plan: &Plan,
    options: Options<'_>,
) -> Result<Outcome, CliError> {
    let started = Instant::now();
    let work = plan_jobs(ctx, inputs, out_dir, plan, options.on_collision)?;
    if work.is_empty() {
        return Err(CliError::Usage(
            "no .step/.stp/.p21/.igs/.iges files found in the inputs".into(),
        ));
    }
    let threads = options.jobs.unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::Usage(format!("cannot start {threads} worker threads: {e}")))?;
    let total = u64::try_from(work.len()).unwrap_or(u64::MAX);
    let bar = if ctx.quiet == 0 && !ctx.report.json() && std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(total);
        if let Ok(style) = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {wide_msg}",
        ) {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    let results: Vec<(FileRecord, Outcome)> = pool.install(|| {
        work.par_iter()
            .map(|job| {
                bar.set_message(display_name(&job.input));
                let started = Instant::now();
                let (record, diagnostics) = convert_one(job, plan);
                tracing::info!(
                    file = %record.file,
                    ok = record.ok,
                    entities = record.entities,
                    ms = started.elapsed().as_millis(),
                    "batch file done"
                );
                bar.suspend(|| {
                    ctx.report.diagnostics(&record.file, &diagnostics);
                    if let (Some(code), Some(message)) = (&record.error_code, &record.error) {
                        let d =
                            Diagnostic::error(code.clone(), message.clone(), Default::default());
                        ctx.report.diagnostic(Some(&record.file), &d);
                    }
                });
                bar.inc(1);
                let outcome = outcome_of(&diagnostics);
                (record, outcome)
            })
            .collect()
    });
    bar.finish_and_clear();
    let records: Vec<&FileRecord> = results.iter().map(|(r, _)| r).collect();
    if let Some(path) = options.report {
        let mut text = String::new();
        for r in &records {
            let line = serde_json::to_string(r)
                .map_err(|e| CliError::Usage(format!("cannot serialise the report: {e}")))?;
            text.push_str(&line);
            text.push('\n');
        }
        write_output(path, &text)?;
    }
    let failed: Vec<&FileRecord> = records.iter().copied().filter(|r| !r.ok).collect();
    let with_errors = results
        .iter()
        .filter(|(r, o)| r.ok && *o == Outcome::Failure)
        .count();
    let empty = records
        .iter()
        .filter(|r| r.ok && r.output.is_none())
        .count();
    let warnings: usize = records.iter().map(|r| r.diagnostics.warnings).sum();
    let written = records.len() - failed.len() - empty;
    let mut summary = format!(
        "nurbsx: converted {written} of {} files in {:.2} s",
        records.len(),
        started.elapsed().as_secs_f64()
    );
    if empty > 0 {
        summary.push_str(&format!(
            "; {empty} without B-spline entities (nothing written)"
        ));
    }
    if with_errors > 0 {
        summary.push_str(&format!(
            "; {with_errors} written without the entities that had errors"
        ));
    }
    if !failed.is_empty() {
        let names: Vec<&str> = failed.iter().take(10).map(|r| r.file.as_str()).collect();
        summary.push_str(&format!(
            "; {} failed: {}{}",
            failed.len(),
            names.join(", "),
            if failed.len() > names.len() {
                ", ..."
            } else {
                ""
            }
        ));
    }
    if warnings > 0 {
        summary.push_str(&format!("; {warnings} warnings"));
    }
    ctx.report.summary(&summary);
    Ok(if failed.is_empty() && with_errors == 0 {
        Outcome::Success
    } else {
        Outcome::Failure
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{ConvertRequest, Settings};

    #[test]
    fn plans_keep_the_folder_layout_and_refuse_or_number_collisions() {
        let root = std::env::temp_dir().join(format!("nurbsx-plan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("in/sub")).unwrap();
        std::fs::create_dir_all(root.join("in/out")).unwrap();
        for f in [
            "in/a.igs",
            "in/a.STP",
            "in/sub/b.iges",
            "in/notes.txt",
            "in/out/old.step",
        ] {
            std::fs::write(root.join(f), "x").unwrap();
        }
        let plan = Plan {
            request: ConvertRequest {
                to: Some(crate::exchange::Format::Step),
                ..ConvertRequest::default()
            },
            settings: Settings::default(),
        };
        // The output folder inside the input folder is not searched.
        let out = root.join("in/out");
        let ctx = Context {
            settings: Settings::default(),
            quiet: 0,
            color: crate::cli::args::ColorArg::Never,
            report: crate::cli::report::Reporter::silent(),
        };
        let refused = plan_jobs(&ctx, &[root.join("in")], &out, &plan, CollisionArg::Error);
        match refused {
            Err(CliError::Usage(m)) => assert!(m.contains("a.STP") && m.contains("a.igs"), "{m}"),
            other => panic!("{other:?}"),
        }
        let jobs = plan_jobs(
            &ctx,
            &[root.join("in")],
            &out,
            &plan,
            CollisionArg::Overwrite,
        )
        .unwrap();
        assert_eq!(jobs.len(), 2);
        assert_eq!(
            (&jobs[0].input, &jobs[0].output),
            (&root.join("in/a.igs"), &out.join("a.step"))
        );
        let jobs = plan_jobs(&ctx, &[root.join("in")], &out, &plan, CollisionArg::Rename).unwrap();
        let pairs: Vec<(PathBuf, PathBuf)> =
            jobs.into_iter().map(|j| (j.input, j.output)).collect();
        assert_eq!(
            pairs,
            vec![
                (root.join("in/a.STP"), out.join("a.step")),
                (root.join("in/a.igs"), out.join("a-2.step")),
                (root.join("in/sub/b.iges"), out.join("sub/b.step")),
            ]
        );
        let _ = std::fs::remove_dir_all(&root);
    }
}
