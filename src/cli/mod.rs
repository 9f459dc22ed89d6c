//! # The `nurbsx` command-line front end
//!
//! Parse, then plan, then run (as ripgrep does): [`args`] turns the command line into typed
//! values (clap), each command module checks what it was given and plans the work, and the
//! work itself is a call into [`crate::pipeline`], the same pipeline the HTTP service uses.
//! This module holds no conversion logic: it reads files, calls the pipeline, and prints.
//!
//! Exit codes (also in every `--help` and README.md):
//!
//! | code | meaning |
//! | --- | --- |
//! | 0 | success (validate: every file valid) |
//! | 1 | input invalid or unreadable, conversion or verification failed, any batch file failed |
//! | 2 | usage error (bad flag or value) or I/O error (missing file, unwritable output) |
//!
//! A [`PipelineError`] maps by its kind: [`ErrorKind::Usage`] to 2, every other kind to 1.
//! Errors print as one line on stderr, `file:line:col: error[code]: message` when the pipeline
//! located them, else `error: message`; never a backtrace. A closed stdout (`| head`) ends the
//! program quietly.

pub mod args;
mod batch;
mod convert;
mod evaluate;
mod inspect;
mod modify;
mod output;

use std::io::{self, IsTerminal, Read, Write};
use std::path::Path;
use std::process::ExitCode;

use clap::Parser;

use crate::pipeline::{ErrorKind, InputKind, PipelineError, Settings};
use args::{Cli, Command, GlobalArgs, LogFormat};

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

    /// The one line printed on stderr (without a trailing newline); `None` for a closed pipe.
    pub fn message(&self) -> Option<String> {
        match self {
            CliError::Pipeline { file, error } => Some(match file {
                Some(f) => output::diagnostic_line(f, &error.diagnostic),
                None => format!("error: {}", error.diagnostic),
            }),
            CliError::Usage(m) => Some(format!("error: {m}")),
            CliError::Io { context, source } => Some(format!("error: {context}: {source}")),
            CliError::Stdout(e) if e.kind() == io::ErrorKind::BrokenPipe => None,
            CliError::Stdout(e) => Some(format!("error: cannot write to standard output: {e}")),
            CliError::Quiet(_) => None,
        }
    }
}

/// The exit code of a pipeline error kind: [`ErrorKind::Usage`] 2, every other kind 1.
pub fn exit_code_of(kind: ErrorKind) -> u8 {
    match kind {
        ErrorKind::Usage => 2,
        ErrorKind::UnknownFormat | ErrorKind::Invalid | ErrorKind::Limit | ErrorKind::Geometry => 1,
    }
}

/// Entry point of the `nurbsx` binary.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version go to stdout with exit 0; usage errors to stderr with exit 2.
            let _ = e.print();
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
    };
    init_logging(&cli.global);
    match run(cli) {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::Failure) => ExitCode::from(1),
        Err(CliError::Stdout(e)) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(line) = e.message() {
                let _ = writeln!(io::stderr().lock(), "{line}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// Runs a parsed command line.
fn run(cli: Cli) -> Result<Outcome, CliError> {
    let settings = settings_from(&cli.global);
    let ctx = Context {
        settings,
        quiet: cli.global.quiet,
        verbose: cli.global.verbose,
    };
    match cli.command {
        Command::Convert(a) => convert::run(&ctx, a),
        Command::Info(a) => inspect::info(&ctx, a),
        Command::Validate(a) => inspect::validate(&ctx, a),
        Command::Evaluate(a) => evaluate::run(&ctx, a),
        Command::Elevate(a) => modify::elevate(&ctx, a),
        Command::Clamp(a) => modify::clamp(&ctx, a, true),
        Command::Unclamp(a) => modify::clamp(&ctx, a, false),
        Command::InsertKnot(a) => modify::insert_knot(&ctx, a),
        Command::Tessellate(a) => modify::tessellate(&ctx, a),
        Command::Serve(a) => serve(&ctx, a),
    }
}

/// What every command needs besides its own arguments.
#[derive(Debug, Clone)]
pub struct Context {
    /// Pipeline limits and policies.
    pub settings: Settings,
    /// `-q` count.
    pub quiet: u8,
    /// `-v` count.
    pub verbose: u8,
}

impl Context {
    /// Prints reader/writer diagnostics for a file on stderr (errors and warnings; info
    /// notes only with -v; nothing with -qq, warnings hidden with -q).
    pub fn print_diagnostics(&self, file: &str, diagnostics: &[crate::exchange::Diagnostic]) {
        use crate::exchange::Severity;
        let mut err = io::stderr().lock();
        for d in diagnostics {
            let show = match d.severity {
                Severity::Error => self.quiet < 2,
                Severity::Warning => self.quiet == 0,
                Severity::Info => self.verbose > 0,
            };
            if show {
                let _ = writeln!(err, "{}", output::diagnostic_line(file, d));
            }
        }
    }
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
fn init_logging(g: &GlobalArgs) {
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
        .with_ansi(io::stderr().is_terminal());
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
    if is_dash(path) {
        let mut out = io::stdout().lock();
        return out
            .write_all(text.as_bytes())
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
    std::fs::write(path, text).map_err(io_err)
}

/// Writes one line to stderr, ignoring failures (there is nowhere else to report them).
pub fn eprint_line(line: &str) {
    let _ = writeln!(io::stderr().lock(), "{line}");
}

/// Writes text to standard output (a closed pipe is reported as [`CliError::Stdout`]).
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(CliError::Stdout)
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
