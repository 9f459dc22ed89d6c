//! `nurbsx help`, `nurbsx completions` and `nurbsx man`: everything generated from the one
//! clap definition in [`super::args`], so help, completions and man pages cannot disagree.

use std::io::IsTerminal;
use std::path::Path;

use clap::CommandFactory;

use super::args::{Cli, CompletionsArgs, EXIT_CODES, HelpArgs, LIMITS, ManArgs};
use super::{CliError, Context, Outcome, print_stdout, write_bytes};

/// The error codes by family, with their exit code and HTTP status (`nurbsx help
/// exit-codes`; README.md has the same table).
pub const ERROR_CODES: &str = "\
Error codes (in `error[code]` and in JSON as \"code\"), by family:
  code                         exit  HTTP  when
  usage                        2     -     bad flag or value
  request.*                    -     400   malformed HTTP request
  entity.not_found             2     400   no entity with that id
  evaluate.domain              2     400   a parameter outside the entity's domain
  insert_knot.domain           2     -     a knot outside the entity's domain
  insert_knot.multiplicity     2     -     the knot cannot be inserted that often
  io                           2     -     missing file, unreadable or unwritable path
  limit.*                      1     413   a --max-* limit was exceeded (nurbsx help limits)
  format.unknown               1     415   not STEP, IGES or model JSON (says what it starts with)
  format.empty, format.binary  1     415   an empty file; binary data
  format.other                 1     415   another format: PDF, DXF, STL, ZIP, gzip, STEP-XML ...
  encoding.utf16, .utf32       1     415   UTF-16/UTF-32 text (STEP and IGES are 8-bit text)
  format.mismatch, *.syntax,   1     422   unreadable file or invalid geometry
    geometry.invalid, ...
  verify.*                     1     422   the re-read output deviates from the input
An error diagnostic about one entity (that entity is left out, the others are read) makes
the exit code 1 in every command, after the result is printed or written.";

/// What goes where (`nurbsx help output`; README.md says the same).
pub const OUTPUT_POLICY: &str = "\
Output:
  stdout  the result: info's table, validate's verdicts (or its JSON/JUnit/SARIF
          document), evaluate's values, a file written to `-o -`, help, completions, man
  stderr  diagnostics (`file:line:col: severity[code]: message`), summaries (what a
          command read, wrote, left out and verified) and the final error line, each once;
          also the logs (-v, RUST_LOG) and the batch progress bar (on a terminal)

  When a JSON document is asked for (info --json, evaluate --json, validate --format
  json|junit|sarif), the diagnostics are inside the document instead of on stderr.

Filtering (stderr and documents alike):
  default              errors and warnings
  -v                   also informational notes (and info logs)
  -q                   errors only (summaries stay)
  -qq                  nothing but the final error line
  --min-severity LEVEL error, warning or info; wins over -q and -v

  --log-format json    every stderr line is a JSON object: {\"type\": \"diagnostic\",
                       \"file\", \"severity\", \"code\", \"message\", \"location\"},
                       {\"type\": \"summary\", \"message\"}, or a tracing log record
  --color WHEN         auto (a terminal, NO_COLOR unset), always, never";

/// The limit options from their own definitions: flag, value name, environment variable
/// and help text.
fn limit_options() -> Vec<[String; 4]> {
    Cli::command()
        .get_arguments()
        .filter(|a| a.get_help_heading() == Some(LIMITS))
        .map(|arg| {
            [
                format!("--{}", arg.get_long().unwrap_or_default()),
                arg.get_value_names()
                    .and_then(|v| v.first())
                    .map(|v| v.to_string())
                    .unwrap_or_default(),
                arg.get_env()
                    .map(|e| e.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                arg.get_help().map(|h| h.to_string()).unwrap_or_default(),
            ]
        })
        .collect()
}

/// What the limits are, before the list.
const LIMITS_INTRO: &str = "\
Limits (global options: before or after the command; each also an environment
variable, which a flag overrides; 0 is refused). Exceeding one is an error with a
`limit.*` code and exit code 1, reported before the work or memory it would cost.";

/// The `nurbsx help limits` page.
pub fn limits_page() -> String {
    use std::fmt::Write as _;
    let mut s = format!("{LIMITS_INTRO}\n\n");
    for [flag, value, env, help] in limit_options() {
        let _ = writeln!(s, "  {flag} {value}  [env: {env}]");
        let _ = writeln!(s, "      {}", help.replace('\n', "\n      "));
    }
    s
}

/// Text for roff: backslashes, hyphens (which roff may turn into dashes) and control
/// characters at the start of a line escaped.
fn roff_text(text: &str) -> String {
    text.lines()
        .map(|line| {
            let escaped = line.replace('\\', "\\e").replace('-', "\\-");
            if escaped.starts_with(['.', '\'']) {
                format!("\\&{escaped}")
            } else {
                escaped
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The sections the program's man page adds to clap's: the limits (hidden from the
/// options, as from `--help`) and the exit status.
fn man_extra_sections() -> String {
    use std::fmt::Write as _;
    let mut s = format!(".SH LIMITS\n{}\n", roff_text(LIMITS_INTRO));
    for [flag, value, env, help] in limit_options() {
        let _ = writeln!(
            s,
            ".TP\n\\fB{}\\fR \\fI{}\\fR [env: {}]\n{}",
            roff_text(&flag),
            roff_text(&value),
            roff_text(&env),
            roff_text(&help)
        );
    }
    let _ = writeln!(
        s,
        ".SH \"EXIT STATUS\"\n.nf\n{}\n\n{}\n.fi",
        roff_text(EXIT_CODES),
        roff_text(ERROR_CODES)
    );
    s
}

/// Renders a styled help text for stdout, coloured as `--color` and the terminal say.
fn styled_for_stdout(ctx: &Context, text: &clap::builder::StyledStr) -> String {
    if super::report::color_wanted(ctx.color, std::io::stdout().is_terminal()) {
        text.ansi().to_string()
    } else {
        text.to_string()
    }
}

/// `nurbsx help [COMMAND|TOPIC]`: as `cargo help`, the full help of the program or of a
/// command, or one of the topics.
pub fn help(ctx: &Context, a: HelpArgs) -> Result<Outcome, CliError> {
    let text = match a.topic.as_deref() {
        None => styled_for_stdout(ctx, &Cli::command().render_long_help()),
        Some("limits") => limits_page(),
        Some("exit-codes") => format!("{EXIT_CODES}\n\n{ERROR_CODES}\n"),
        Some("output") => format!("{OUTPUT_POLICY}\n"),
        Some(name) => {
            let mut cmd = Cli::command();
            cmd.build();
            match cmd.find_subcommand_mut(name) {
                Some(sub) => styled_for_stdout(ctx, &sub.render_long_help()),
                None => {
                    let names: Vec<&str> =
                        cmd.get_subcommands().map(clap::Command::get_name).collect();
                    return Err(CliError::Usage(format!(
                        "no command or help topic `{name}`; commands: {}; topics: limits, \
                         exit-codes, output",
                        names.join(", ")
                    )));
                }
            }
        }
    };
    print_stdout(&text)?;
    Ok(Outcome::Success)
}

/// `nurbsx completions SHELL`.
pub fn completions(a: CompletionsArgs) -> Result<Outcome, CliError> {
    let mut cmd = Cli::command();
    let mut out = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "nurbsx", &mut out);
    write_bytes(Path::new("-"), &out)?;
    Ok(Outcome::Success)
}

/// The man page of the program (`None`) or of one command, as roff.
fn man_page(command: Option<&str>) -> Result<Vec<u8>, CliError> {
    let mut cmd = Cli::command();
    cmd.build();
    let page = match command {
        None => cmd,
        Some(name) => cmd.find_subcommand(name).cloned().ok_or_else(|| {
            CliError::Usage(format!(
                "no command `{name}` (see `nurbsx --help` for the list)"
            ))
        })?,
    };
    let mut out = Vec::new();
    clap_mangen::Man::new(page)
        .render(&mut out)
        .map_err(|source| CliError::Io {
            context: "cannot render the man page".into(),
            source,
        })?;
    if command.is_none() {
        out.extend_from_slice(man_extra_sections().as_bytes());
    }
    Ok(out)
}

/// `nurbsx man [COMMAND]` or `nurbsx man --out-dir DIR`.
pub fn man(a: ManArgs) -> Result<Outcome, CliError> {
    let Some(dir) = a.out_dir else {
        write_bytes(Path::new("-"), &man_page(a.command.as_deref())?)?;
        return Ok(Outcome::Success);
    };
    let mut cmd = Cli::command();
    cmd.build();
    write_bytes(&dir.join("nurbsx.1"), &man_page(None)?)?;
    for sub in cmd.get_subcommands() {
        let name = sub.get_name();
        write_bytes(
            &dir.join(format!("nurbsx-{name}.1")),
            &man_page(Some(name))?,
        )?;
    }
    Ok(Outcome::Success)
}
