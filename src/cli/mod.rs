//! # The `nurbsx` command-line front end
//!
//! Parse, then plan, then run (as ripgrep does): [`args`] turns the command line into typed
//! values (clap), each command module checks what it was given and plans the work, and the
//! work itself is a call into [`crate::pipeline`], the same pipeline the HTTP service uses.
//! This module holds no conversion logic: it reads files, calls the pipeline, and prints.
//!
//! Output policy (also `nurbsx help output` and README.md): results on stdout; diagnostics,
//! summaries and the final error line on stderr through `report::Reporter` (or inside the
//! document when a JSON, JUnit or SARIF document is asked for), each once.
//!
//! Exit codes (also `nurbsx help exit-codes` and README.md):
//!
//! | code | meaning |
//! | --- | --- |
//! | 0 | success, and no error diagnostic was reported (validate: every file valid) |
//! | 1 | the input is invalid, unreadable or over a limit, an error diagnostic was reported, the conversion or verification failed, or (batch) a file failed |
//! | 2 | usage error (bad flag or value, unknown entity, parameter or knot outside the domain) or I/O error |
//!
//! A [`PipelineError`] maps by its kind: [`ErrorKind::Usage`] to 2, every other kind to 1.
//! A closed stdout (`| head`) ends the program quietly.

pub mod args;
mod batch;
mod convert;
mod evaluate;
mod help;
mod inspect;
mod measure;
mod modify;
mod output;
mod report;

use std::io::{self, IsTerminal, Read, Write};
use std::path::Path;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches};

use crate::exchange::{Diagnostic, Severity};
use crate::pipeline::{ErrorKind, InputKind, Loaded, PipelineError, Settings};
use args::{Cli, ColorArg, Command, GlobalArgs, LogFormat};
use report::Reporter;

/// How a command ended when it did not fail outright.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Exit 0.
    Success,
    /// Exit 1: something was invalid or failed, and that was already reported.
    Failure,
}

/// A failure that ends the command, printed as one line on stderr.
#[derive(Debug)]
pub enum CliError {
    /// A pipeline failure while working on `file` (if there is one).
    Pipeline {
        /// The file the error is about, as the user named it.
        file: Option<String>,
        /// The error.
        error: PipelineError,
    },
    /// A bad combination of arguments (exit 2).
    Usage(String),
    /// Reading or writing a file failed (exit 2).
    Io {
        /// What was being done, e.g. "cannot read `part.step`".
        context: String,
        /// The cause.
        source: io::Error,
    },
    /// Writing to standard output failed (a closed pipe ends quietly).
    Stdout(io::Error),
    /// Exit with this code; what went wrong was already printed.
    Quiet(u8),
}

impl CliError {
    /// A pipeline error about a file.
    pub fn pipeline(file: &Path, error: PipelineError) -> Self {
        CliError::Pipeline {
            file: Some(display_name(file)),
            error,
        }
    }

    /// The exit code: usage and I/O errors 2, everything else 1.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Pipeline { error, .. } => exit_code_of(error.kind),
            CliError::Usage(_) | CliError::Io { .. } | CliError::Stdout(_) => 2,
            CliError::Quiet(code) => *code,
        }
    }

    /// The file and diagnostic printed on stderr; `None` for a closed pipe or a quiet exit.
    pub fn diagnostic(&self) -> Option<(Option<&str>, Diagnostic)> {
        match self {
            CliError::Pipeline { file, error } => Some((file.as_deref(), error.diagnostic.clone())),
            CliError::Usage(m) => Some((None, report::error("usage", m.clone()))),
            CliError::Io { context, source } => {
                Some((None, report::error("io", format!("{context}: {source}"))))
            }
            CliError::Stdout(e) if e.kind() == io::ErrorKind::BrokenPipe => None,
            CliError::Stdout(e) => Some((
                None,
                report::error("io", format!("cannot write to standard output: {e}")),
            )),
            CliError::Quiet(_) => None,
        }
    }

    /// The message alone (for reports that carry it as text).
    pub fn message(&self) -> Option<String> {
        self.diagnostic().map(|(_, d)| d.message)
    }
}

/// The exit code of a pipeline error kind: [`ErrorKind::Usage`] 2, every other kind 1.
pub fn exit_code_of(kind: ErrorKind) -> u8 {
    match kind {
        ErrorKind::Usage => 2,
        ErrorKind::UnknownFormat | ErrorKind::Invalid | ErrorKind::Limit | ErrorKind::Geometry => 1,
    }
}

/// The value of a global option in the raw arguments (`--name value` or `--name=value`),
/// read before clap parses them, so that help and usage errors follow `--color` and
/// `--log-format` too. The last occurrence wins, as in clap; `--` ends the options.
fn early_option(args: &[std::ffi::OsString], name: &str) -> Option<String> {
    let mut found = None;
    let mut it = args.iter().skip(1);
    while let Some(arg) = it.next() {
        let Some(arg) = arg.to_str() else { continue };
        if arg == "--" {
            break;
        }
        if arg == name {
            found = it.next().and_then(|v| v.to_str()).map(str::to_owned);
        } else if let Some(v) = arg.strip_prefix(name).and_then(|r| r.strip_prefix('=')) {
            found = Some(v.to_owned());
        }
    }
    found
}

/// The clap colour choice for help and usage errors (on stdout and stderr).
fn clap_color(choice: ColorArg, stream_is_terminal: bool) -> clap::ColorChoice {
    if report::color_wanted(choice, stream_is_terminal) {
        clap::ColorChoice::Always
    } else {
        clap::ColorChoice::Never
    }
}

/// Entry point of the `nurbsx` binary.
pub fn main() -> ExitCode {
    let raw: Vec<std::ffi::OsString> = std::env::args_os().collect();
    let color = match early_option(&raw, "--color").as_deref() {
        Some("always") => ColorArg::Always,
        Some("never") => ColorArg::Never,
        _ => ColorArg::Auto,
    };
    let json_log = early_option(&raw, "--log-format").as_deref() == Some("json");
    let parsed = Cli::command()
        .color(clap_color(color, io::stdout().is_terminal()))
        .try_get_matches_from(&raw)
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e, color, json_log),
    };
    let reporter = Reporter::from_args(&cli.global);
    init_logging(&cli.global, reporter.color());
    match run(cli, &reporter) {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::Failure) => ExitCode::from(1),
        Err(e) => {
            if let Some((file, d)) = e.diagnostic() {
                reporter.fatal(file, &d);
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// Ends on a clap outcome: help and version on stdout with exit 0; a usage error on stderr
/// (a JSON line with `--log-format json`) with exit 2.
fn clap_exit(e: &clap::Error, color: ColorArg, json_log: bool) -> ExitCode {
    let code = u8::try_from(e.exit_code()).unwrap_or(2);
    if !e.use_stderr() {
        let _ = e.print();
        return ExitCode::from(code);
    }
    if json_log {
        let message = e.render().to_string();
        let d = report::error("usage", message.trim_end().to_owned());
        Reporter::json_only().fatal(None, &d);
    } else {
        // The error was built for stdout's colour; stderr decides for itself.
        let styled = e.render();
        let text = if report::color_wanted(color, io::stderr().is_terminal()) {
            styled.ansi().to_string()
        } else {
            styled.to_string()
        };
        let _ = write!(io::stderr().lock(), "{text}");
    }
    ExitCode::from(code)
}

/// Runs a parsed command line.
fn run(cli: Cli, reporter: &Reporter) -> Result<Outcome, CliError> {
    let settings = settings_from(&cli.global);
    let ctx = Context {
        settings,
        quiet: cli.global.quiet,
        color: cli.global.color,
        report: reporter.clone(),
    };
    let result = match cli.command {
        Command::Convert(a) => convert::run(&ctx, a),
        Command::Info(a) => inspect::info(&ctx, a),
        Command::Validate(a) => inspect::validate(&ctx, a),
        Command::Evaluate(a) => evaluate::run(&ctx, a),
        Command::Elevate(a) => modify::elevate(&ctx, a),
        Command::Clamp(a) => modify::clamp(&ctx, a, true),
        Command::Unclamp(a) => modify::clamp(&ctx, a, false),
        Command::InsertKnot(a) => modify::insert_knot(&ctx, a),
        Command::Refine(a) => modify::refine(&ctx, a),
        Command::Reduce(a) => modify::reduce(&ctx, a),
        Command::RemoveKnots(a) => modify::remove_knots(&ctx, a),
        Command::Decompose(a) => modify::decompose(&ctx, a),
        Command::Split(a) => modify::split(&ctx, a),
        Command::Join(a) => modify::join(&ctx, a),
        Command::Reverse(a) => modify::reverse(&ctx, a),
        Command::Reparameterize(a) => modify::reparameterize(&ctx, a),
        Command::Transform(a) => modify::transform(&ctx, a),
        Command::Iso(a) => modify::iso(&ctx, a),
        Command::Periodic(a) => modify::periodic(&ctx, a),
        Command::DerivativeCurve(a) => modify::derivative_curve(&ctx, a),
        Command::Make(a) => modify::make(&ctx, a),
        Command::Fit(a) => modify::fit(&ctx, a),
        Command::Measure(a) => measure::measure(&ctx, a),
        Command::Compare(a) => measure::compare(&ctx, a),
        Command::Tessellate(a) => modify::tessellate(&ctx, a),
        Command::Serve(a) => serve(&ctx, a),
        Command::Help(a) => help::help(&ctx, a),
        Command::Completions(a) => help::completions(a),
        Command::Man(a) => help::man(a),
    };
    match result {
        // A closed pipe is how `| head` says it has enough: not a failure.
        Err(CliError::Stdout(e)) if e.kind() == io::ErrorKind::BrokenPipe => Ok(Outcome::Success),
        other => other,
    }
}

/// What every command needs besides its own arguments.
#[derive(Debug, Clone)]
pub struct Context {
    /// Pipeline limits and policies.
    pub settings: Settings,
    /// `-q` count (the progress bar is hidden with any).
    pub quiet: u8,
    /// `--color` (for help printed on stdout).
    pub color: ColorArg,
    /// The writer of stderr.
    pub report: Reporter,
}

/// Exit 1 when any error diagnostic was reported (an entity could not be read, or broke a
/// limit, and is missing from the result), else exit 0.
pub fn outcome_of(diagnostics: &[Diagnostic]) -> Outcome {
    if diagnostics.iter().any(|d| d.severity == Severity::Error) {
        Outcome::Failure
    } else {
        Outcome::Success
    }
}

/// A warning when a file's extension names another format than its content (the content
/// decides; `.json` and unknown extensions are not contradicted by anything).
pub fn extension_warning(path: &Path, found: InputKind) -> Option<Diagnostic> {
    let declared = if is_dash(path) {
        None
    } else {
        InputKind::from_path(path)
    }?;
    (declared != found && declared != InputKind::Json).then(|| {
        Diagnostic::warning(
            "format.extension",
            format!(
                "the extension says {} but the content is {}; read as {}",
                declared.name().to_ascii_uppercase(),
                found.name().to_ascii_uppercase(),
                found.name().to_ascii_uppercase()
            ),
            Default::default(),
        )
    })
}

/// Why the entity asked for (`None`: any entity) is missing from a document, when the reader
/// refused it: its first error diagnostic (a limit, invalid data), as that error's kind.
pub fn reader_error(
    doc: &crate::exchange::Document,
    wanted: Option<&str>,
) -> Option<PipelineError> {
    doc.diagnostics
        .iter()
        .find(|d| {
            d.severity == Severity::Error
                && match (wanted, d.location.entity.as_deref()) {
                    (None, _) => true,
                    (Some(w), Some(id)) => id == w || id.trim_start_matches(['#', 'D']) == w,
                    (Some(_), None) => false,
                }
        })
        .map(|d| PipelineError::from_exchange(d.clone()))
}

/// Reads and loads an input file; the document's diagnostics gain the extension warning.
/// Nothing is printed: the caller shows the diagnostics on stderr or in its document.
pub fn load_file(ctx: &Context, path: &Path) -> Result<Loaded, CliError> {
    let (bytes, hint) = read_input(path, &ctx.settings)?;
    let mut loaded = crate::pipeline::load(&bytes, hint, &ctx.settings)
        .map_err(|e| CliError::pipeline(path, e))?;
    if let Some(w) = extension_warning(path, loaded.kind) {
        loaded.document.diagnostics.insert(0, w);
    }
    Ok(loaded)
}

/// Fills the pipeline settings from the global flags.
fn settings_from(g: &GlobalArgs) -> Settings {
    let mut s = Settings::default();
    if let Some(d) = g.max_degree {
        s.max_degree = d;
        s.import.limits.max_degree = d;
    }
    if let Some(b) = g.max_input_bytes {
        s.import.limits.max_input_bytes = b;
    }
    let limits = &mut s.import.limits;
    for (flag, field) in [
        (g.max_entities, &mut limits.max_entities),
        (g.max_nesting_depth, &mut limits.max_nesting_depth),
        (g.max_params, &mut limits.max_params_per_entity),
        (g.max_poles, &mut limits.max_poles),
    ] {
        if let Some(v) = flag {
            *field = v;
        }
    }
    for (flag, field) in [
        (g.max_eval_points, &mut s.max_eval_points),
        (g.max_elevate_by, &mut s.max_elevate_by),
        (g.max_mesh_vertices, &mut s.max_mesh_vertices),
    ] {
        if let Some(v) = flag {
            *field = v;
        }
    }
    s
}

/// Sets up tracing on stderr: RUST_LOG if set, else a level from -v/-q.
fn init_logging(g: &GlobalArgs, color: bool) {
    use tracing_subscriber::EnvFilter;
    let default = match (g.verbose, g.quiet) {
        (0, 0) => "warn",
        (1, _) => "info",
        (2, _) => "debug",
        (v, _) if v > 2 => "trace",
        (_, 1) => "error",
        _ => "off",
    };
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(default));
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(io::stderr)
        .with_ansi(color);
    // A second initialisation (never in the binary) is harmless: keep the first.
    let _ = match g.log_format {
        LogFormat::Text => builder.try_init(),
        LogFormat::Json => builder.json().try_init(),
    };
}

/// The name a path is shown by: as given, `<stdin>` for `-`.
pub fn display_name(path: &Path) -> String {
    if is_dash(path) {
        "<stdin>".to_owned()
    } else {
        path.display().to_string()
    }
}

/// Whether the path is `-` (standard input or output).
pub fn is_dash(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Reads an input file (or standard input for `-`), refusing files above the input limit
/// before reading them, and returns the bytes and the format hint from the extension.
pub fn read_input(
    path: &Path,
    settings: &Settings,
) -> Result<(Vec<u8>, Option<InputKind>), CliError> {
    let limit = settings.import.limits.max_input_bytes;
    let too_big = |size: u64| {
        CliError::pipeline(
            path,
            PipelineError::new(
                ErrorKind::Limit,
                "limit.input_bytes",
                format!("input is {size} bytes, above the limit of {limit} bytes"),
                Default::default(),
            ),
        )
    };
    let cap = u64::try_from(limit).unwrap_or(u64::MAX).saturating_add(1);
    let bytes = if is_dash(path) {
        let mut buf = Vec::new();
        io::stdin()
            .lock()
            .take(cap)
            .read_to_end(&mut buf)
            .map_err(|source| CliError::Io {
                context: "cannot read standard input".into(),
                source,
            })?;
        buf
    } else {
        let io_err = |source| CliError::Io {
            context: format!("cannot read `{}`", path.display()),
            source,
        };
        let file = std::fs::File::open(path).map_err(io_err)?;
        let meta = file.metadata().map_err(io_err)?;
        if meta.is_dir() {
            return Err(CliError::Usage(format!(
                "`{}` is a folder (only `convert --out-dir` takes folders)",
                path.display()
            )));
        }
        if meta.len() > cap.saturating_sub(1) {
            return Err(too_big(meta.len()));
        }
        let mut buf = Vec::new();
        file.take(cap).read_to_end(&mut buf).map_err(io_err)?;
        buf
    };
    let len = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    if len > cap.saturating_sub(1) {
        return Err(too_big(len));
    }
    let hint = if is_dash(path) {
        None
    } else {
        InputKind::from_path(path)
    };
    Ok((bytes, hint))
}

/// Writes output text to a file (creating missing parent folders) or standard output (`-`).
pub fn write_output(path: &Path, text: &str) -> Result<(), CliError> {
    write_bytes(path, text.as_bytes())
}

/// Writes bytes to a file (creating missing parent folders) or standard output (`-`).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    if is_dash(path) {
        let mut out = io::stdout().lock();
        return out
            .write_all(bytes)
            .and_then(|()| out.flush())
            .map_err(CliError::Stdout);
    }
    let io_err = |source| CliError::Io {
        context: format!("cannot write `{}`", path.display()),
        source,
    };
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(io_err)?;
    }
    std::fs::write(path, bytes).map_err(io_err)
}

/// Writes text to standard output (a closed pipe is reported as [`CliError::Stdout`]).
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    write_bytes(Path::new("-"), text.as_bytes())
}

/// `nurbsx serve`: fills the service configuration and runs it.
fn serve(ctx: &Context, a: args::ServeArgs) -> Result<Outcome, CliError> {
    if a.max_body == 0
        || a.timeout.is_zero()
        || a.max_reply_bytes == 0
        || a.max_upload_bytes == 0
        || a.min_upload_rate == 0
        || a.header_timeout.is_zero()
    {
        return Err(CliError::Usage(
            "--max-body, --timeout, --max-reply-bytes, --max-upload-bytes, --min-upload-rate \
             and --header-timeout must be above zero"
                .into(),
        ));
    }
    let mut config = crate::service::ServeConfig {
        addr: a.addr,
        max_body_bytes: a.max_body,
        max_reply_bytes: a.max_reply_bytes,
        request_timeout: a.timeout,
        max_uploads: usize::try_from(a.max_uploads).unwrap_or(usize::MAX),
        max_upload_bytes: a.max_upload_bytes,
        min_upload_rate: u64::try_from(a.min_upload_rate).unwrap_or(u64::MAX),
        header_timeout: a.header_timeout,
        drain: a.drain,
        settings: ctx.settings.clone(),
        ..Default::default()
    };
    if let Some(n) = a.concurrency {
        config.max_concurrency = usize::try_from(n).unwrap_or(1);
    }
    tracing::info!(addr = %config.addr, "starting the HTTP service");
    crate::service::serve(config)
        .map(|()| Outcome::Success)
        .map_err(|source| CliError::Io {
            context: format!("the service on {} stopped", a.addr),
            source,
        })
}
