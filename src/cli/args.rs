//! Command-line arguments (clap derive). Parsing only: every value is checked here (units,
//! byte sizes, durations, parameter tuples), and the commands receive typed values.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use clap::{ArgAction, Args, Parser, Subcommand, ValueEnum};

use crate::exchange::{LengthUnit, StepSchema};
use crate::pipeline::Direction;

/// The exit-code table of the top-level help and of `nurbsx help exit-codes` (a macro, so
/// that `concat!` can put it into the help text).
macro_rules! exit_codes {
    () => {
        "\
Exit codes (every command):
  0  success, and no error diagnostic (validate: every file valid)
  1  the input is invalid, unreadable or over a limit (limit.*), an entity could not be
     read (error diagnostic), the conversion or its verification failed, or (batch) any
     file failed
  2  usage error (bad flag or value, unknown entity, parameter or knot outside the
     domain) or I/O error (missing file, unwritable output)"
    };
}

/// The exit-code table.
pub const EXIT_CODES: &str = exit_codes!();

const TOP_HELP: &str = concat!(
    "\
Examples:
  nurbsx convert part.igs -o part.step --verify
  nurbsx convert drawings/ --out-dir converted/ --to step --report report.jsonl
  nurbsx info part.step
  nurbsx validate --format sarif *.step > results.sarif
  nurbsx evaluate circle.json --at 0.25 --at 0.5 --json

",
    exit_codes!(),
    "

More help:
  nurbsx help COMMAND      the full help of a command
  nurbsx help limits       the --max-* limits (global options, also environment variables)
  nurbsx help exit-codes   the exit codes and error codes of every command
  nurbsx help output       what goes to stdout and stderr, -q, --min-severity, --log-format
  nurbsx completions SHELL shell completions (bash, zsh, fish, powershell, elvish)
  nurbsx man [COMMAND]     man pages (roff)"
);

/// `nurbsx`: exact NURBS exchange between IGES 5.3 and STEP.
#[derive(Debug, Parser)]
#[command(
    name = "nurbsx",
    version,
    about = "Exact NURBS exchange between IGES 5.3 and STEP (ISO 10303-21/42)",
    long_about = "Exact NURBS exchange between IGES 5.3 and STEP (ISO 10303-21 files with \
                  ISO 10303-42 geometry): every curve and surface with an exact rational form \
                  (B-splines, lines, conics, quadrics, swept surfaces) read into one NURBS \
                  model; convert, inspect, validate, evaluate, construct and modify it without \
                  losing a bit.",
    after_help = TOP_HELP,
    propagate_version = true,
    disable_help_subcommand = true,
    max_term_width = 100
)]
pub struct Cli {
    /// Options that apply to every command.
    #[command(flatten)]
    pub global: GlobalArgs,
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// Output, logging and limits, accepted before or after the command name. The limits are
/// hidden from every command's `--help` and listed once by `nurbsx help limits`.
#[derive(Debug, Args)]
pub struct GlobalArgs {
    /// More output on stderr: -v shows info notes and info logs, -vv debug logs, -vvv trace.
    #[arg(short, long, action = ArgAction::Count, global = true, help_heading = "Global options")]
    pub verbose: u8,
    /// Less output on stderr: -q shows errors only, -qq also hides summaries (the one line
    /// that explains a failing exit code is always printed).
    #[arg(short, long, action = ArgAction::Count, global = true, conflicts_with = "verbose", help_heading = "Global options")]
    pub quiet: u8,
    /// The least severe diagnostic shown (default warning; info with -v, error with -q).
    #[arg(
        long,
        value_enum,
        value_name = "LEVEL",
        global = true,
        help_heading = "Global options"
    )]
    pub min_severity: Option<SeverityArg>,
    /// Colour on stderr and in help: auto (on a terminal, unless NO_COLOR is set), always,
    /// never.
    #[arg(long, value_enum, value_name = "WHEN", default_value_t = ColorArg::Auto, global = true, help_heading = "Global options")]
    pub color: ColorArg,
    /// Format of everything nurbsx writes on stderr (diagnostics, summaries, logs).
    #[arg(long, value_enum, default_value_t = LogFormat::Text, global = true, help_heading = "Global options")]
    pub log_format: LogFormat,
    /// Highest B-spline degree accepted when reading and produced by operations
    /// (default 25, as Open CASCADE).
    #[arg(long, env = "NURBSX_MAX_DEGREE", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_degree: Option<usize>,
    /// Largest input file accepted, e.g. 512MiB (default 2GiB).
    #[arg(long, env = "NURBSX_MAX_INPUT_BYTES", value_name = "SIZE", value_parser = positive_bytes, global = true, hide = true, help_heading = LIMITS)]
    pub max_input_bytes: Option<usize>,
    /// Most STEP entity instances / IGES directory entries in one file (default 50000000).
    #[arg(long, env = "NURBSX_MAX_ENTITIES", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_entities: Option<usize>,
    /// Deepest nesting of parenthesised STEP lists, 1 to 128 (default 64; real files nest
    /// 3-4 deep).
    #[arg(long, env = "NURBSX_MAX_NESTING_DEPTH", value_name = "N", value_parser = nesting_depth, global = true, hide = true, help_heading = LIMITS)]
    pub max_nesting_depth: Option<usize>,
    /// Most parameters in one STEP instance or IGES entity, list elements included
    /// (default 50000000).
    #[arg(long, env = "NURBSX_MAX_PARAMS", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_params: Option<usize>,
    /// Most control points in one curve or surface (default 25000000).
    #[arg(long, env = "NURBSX_MAX_POLES", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_poles: Option<usize>,
    /// Most parameters evaluated in one `evaluate` call or HTTP request (default 10000000).
    #[arg(long, env = "NURBSX_MAX_EVAL_POINTS", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_eval_points: Option<usize>,
    /// Largest degree elevation in one `elevate` call or request (default 20).
    #[arg(long, env = "NURBSX_MAX_ELEVATE_BY", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_elevate_by: Option<usize>,
    /// Most vertices one tessellation may produce (default 20000000).
    #[arg(long, env = "NURBSX_MAX_MESH_VERTICES", value_name = "N", value_parser = positive, global = true, hide = true, help_heading = LIMITS)]
    pub max_mesh_vertices: Option<usize>,
}

/// The help heading of the limit options (`nurbsx help limits` lists the options under it).
pub const LIMITS: &str = "Limits";

/// A byte-size limit: a size of at least 1 byte.
fn positive_bytes(s: &str) -> Result<usize, String> {
    match parse_bytes(s)? {
        0 => Err("must be at least 1 byte".to_owned()),
        n => Ok(n),
    }
}

/// `--color`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// Colour when the output is a terminal and NO_COLOR is not set.
    Auto,
    /// Always colour.
    Always,
    /// Never colour.
    Never,
}

/// `--min-severity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, ValueEnum)]
pub enum SeverityArg {
    /// Errors only.
    Error,
    /// Errors and warnings.
    Warning,
    /// Everything, informational notes included.
    Info,
}

/// A limit value: a whole number of at least 1 (a limit of 0 would refuse everything).
/// `--max-nesting-depth`: the STEP grammar recurses once per level, so the limit has a
/// ceiling ([`nurbsx_parsers::Limits::MAX_NESTING_DEPTH`]).
fn nesting_depth(s: &str) -> Result<usize, String> {
    let n = positive(s)?;
    let max = nurbsx_parsers::Limits::MAX_NESTING_DEPTH;
    if n > max {
        return Err(format!("must be at most {max}"));
    }
    Ok(n)
}

fn positive(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1".to_owned()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("not a whole number: {e}")),
    }
}

/// How log lines are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LogFormat {
    /// Human-readable lines.
    Text,
    /// One JSON object per line.
    Json,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Convert STEP <-> IGES (one file with -o, or many with --out-dir).
    #[command(
        long_about = "Convert curves and surfaces between STEP and IGES as exact NURBS: \
                      B-spline poles, weights and knots are copied, never approximated; lines, \
                      conics, planes, quadrics, revolutions, extrusions and ruled surfaces \
                      become their exact rational form (README: parameterisation).\n\n\
                      One file: the output format comes from --to or from OUT's extension \
                      (.step/.stp/.p21, .igs/.iges). Many files or folders: give --out-dir; \
                      folders are searched recursively for .step/.stp/.p21/.igs/.iges files, \
                      converted in parallel, and --report writes one JSON line per file.\n\n\
                      Diagnostics (warnings about the input) go to stderr as \
                      `file:line:col: warning[code]: message`, then one summary line: \
                      what was read, written, left out (with the warning that says why) \
                      and verified.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx convert part.igs -o part.step\n",
            "  nurbsx convert part.step -o part.igs --units in --verify=1e-12\n",
            "  nurbsx convert cad/ more.igs --out-dir out/ --to step --report report.jsonl\n\n",
            "Exit codes:\n",
            "  0  converted, or nothing to convert (batch: every file)\n",
            "  1  input invalid or over a limit, conversion or verification failed, or (batch)\n",
            "     any file failed\n",
            "  2  usage or I/O error"
        )
    )]
    Convert(ConvertArgs),
    /// Show the format, units and every B-spline entity of a file.
    #[command(
        long_about = "Show a file's format, schema and length unit, then every B-spline curve \
                      and surface: id (STEP #17, IGES D5), kind, dimension, degree(s), pole \
                      counts, knot layout, rational or not, domain, and the source entity and \
                      line; then what the reader noticed (diagnostics).",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx info part.step\n",
            "  nurbsx info part.igs --json | jq '.entities[].id'\n\n",
            "Exit codes:\n",
            "  0  the file was read\n",
            "  1  the file is not readable STEP, IGES or model JSON, is over a limit, or an\n",
            "     entity could not be read (error diagnostic)\n",
            "  2  usage or I/O error"
        )
    )]
    Info(InfoArgs),
    /// Check files for syntax and geometry errors (for CI).
    #[command(
        long_about = "Check STEP, IGES and model-JSON files: syntax, entity structure and \
                      B-spline geometry (knot vectors, weights, pole counts, flags against \
                      data). Text output is one `file:line:col: error[code]: message` line per \
                      finding (usable as CI annotations); JUnit XML and SARIF 2.1.0 are \
                      available for test reports and code-scanning dashboards.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx validate part.step part.igs\n",
            "  nurbsx validate --strict --format junit cad/*.step > validate.xml\n",
            "  nurbsx validate --format sarif cad/*.igs > validate.sarif\n\n",
            "Exit codes:\n",
            "  0  every file is valid (with --strict: and has no warnings)\n",
            "  1  at least one file is invalid\n",
            "  2  usage or I/O error (e.g. a file does not exist)"
        )
    )]
    Validate(ValidateArgs),
    /// Evaluate a curve or surface at parameters (points, derivatives, normals, curvature).
    #[command(
        long_about = "Evaluate one curve or surface at given parameters: `--at U` for curves, \
                      `--at U,V` for surfaces (repeatable), or `--params FILE` with one tuple \
                      per line (`u`, `u,v` or `u v`) or a JSON array of arrays. IN may be \
                      STEP, IGES or model JSON.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx evaluate circle.json --at 0 --at 0.125 --at 0.25\n",
            "  nurbsx evaluate part.step --entity '#17' --at 0.5,0.5 --normals --json\n",
            "  nurbsx evaluate part.igs --entity D5 --params params.txt --derivatives 2\n\n",
            "Exit codes:\n",
            "  0  evaluated\n",
            "  1  the input is invalid, unreadable or over a limit (limit.*)\n",
            "  2  usage or I/O error (unknown entity, parameter outside the domain, bad tuple)"
        )
    )]
    Evaluate(EvaluateArgs),
    /// Raise the degree without changing the shape (NURBS Book A5.9/A5.10).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx elevate part.step -o part-p5.step --by 2\n",
        "  nurbsx elevate surface.json -o raised.json --by 1 --direction u\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit, or the result would exceed --max-degree\n",
        "  2  usage or I/O error"
    ))]
    Elevate(ElevateArgs),
    /// Make every knot vector clamped (open) without changing the shape.
    #[command(visible_alias = "open", after_help = concat!(
        "Examples:\n",
        "  nurbsx clamp periodic.igs -o clamped.igs\n",
        "  nurbsx clamp curve.json -o clamped.json\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error"
    ))]
    Clamp(SimpleOpArgs),
    /// Make every knot vector unclamped without changing the shape (NURBS Book A12.1).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx unclamp part.step -o unclamped.step\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error"
    ))]
    Unclamp(SimpleOpArgs),
    /// Insert a knot without changing the shape (NURBS Book A5.1/A5.3).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx insert-knot curve.json -o refined.json --at 0.5 --times 2\n",
        "  nurbsx insert-knot part.step -o refined.step --entity '#17' --at 0.3 --direction v\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (knot outside the domain or inserted too often)"
    ))]
    InsertKnot(InsertKnotArgs),
    /// Insert several knots at once without changing the shape (NURBS Book A5.4), or halve
    /// every knot interval (seed 003).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx refine curve.json -o refined.json --knots 0.25,0.5,0.75\n",
        "  nurbsx refine part.step -o refined.step --entity '#17' --knots 0.5 --direction v\n",
        "  nurbsx refine curve.json -o halved.json --halve --knot-intervals\n",
        "  nurbsx refine surface.json -o halved.json --halve --direction both\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (knot outside the domain or inserted too often)"
    ))]
    Refine(RefineArgs),
    /// Lower the degree by one when the shape moves by at most --tolerance (A5.11).
    #[command(
        long_about = "Lower the degree by one (NURBS Book A5.11) when an upper bound of the \
                      deviation stays within --tolerance (model units); the bound reached is \
                      printed per entity. A curve that came from degree elevation comes back \
                      exactly.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx reduce elevated.json -o reduced.json --tolerance 1e-9\n",
            "  nurbsx reduce part.step -o reduced.step --tolerance 0.01 --direction u\n\n",
            "Exit codes:\n",
            "  0  written\n",
            "  1  the input is invalid, or the deviation bound exceeds the tolerance\n",
            "  2  usage or I/O error"
        )
    )]
    Reduce(ReduceArgs),
    /// Remove every interior knot that can go with a change of at most --tolerance (A5.8).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx remove-knots refined.json -o lean.json --tolerance 1e-9\n",
        "  nurbsx remove-knots part.igs -o lean.igs --tolerance 0.001 --entity D5\n\n",
        "Exit codes:\n",
        "  0  written (the number removed is printed per entity)\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error"
    ))]
    RemoveKnots(ToleranceOpArgs),
    /// Split into Bezier segments (curves) or patches (surfaces), exactly (A5.6/A5.7).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx decompose curve.json -o segments.json\n",
        "  nurbsx decompose part.step -o patches.step --entity '#17'\n\n",
        "Entity k of entity ID is named ID.k (patches in u-major order).\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error"
    ))]
    Decompose(EntityOpArgs),
    /// Split at a parameter into two pieces, exactly.
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx split curve.json -o halves.json --at 0.5\n",
        "  nurbsx split part.step -o halves.step --entity '#17' --at 0.3 --direction v\n\n",
        "The pieces of entity ID are named ID.1 and ID.2.\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (parameter not strictly inside the domain)"
    ))]
    Split(SplitArgs),
    /// Join all curves of the input, in order, into one curve.
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx join pieces.json -o joined.json\n",
        "  nurbsx join pieces.igs -o joined.igs --tolerance 1e-6\n\n",
        "Each end must meet the next start within --tolerance; the junction pole is the \n",
        "midpoint of the two ends. Degrees, rationality and dimension must agree.\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid, or a gap exceeds the tolerance\n",
        "  2  usage or I/O error (fewer than two curves)"
    ))]
    Join(JoinArgs),
    /// Reverse the parameter direction (shape unchanged).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx reverse curve.json -o reversed.json\n",
        "  nurbsx reverse part.step -o flipped.step --direction u\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error"
    ))]
    Reverse(SimpleOpArgs),
    /// Map the parameter domain affinely onto [A, B] (shape unchanged).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx reparameterize curve.json -o unit.json --to 0,1\n",
        "  nurbsx reparameterize part.step -o unit.step --to 0,1 --direction v\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (A >= B)"
    ))]
    Reparameterize(ReparameterizeArgs),
    /// Move, rotate and scale (or apply a 3x4 matrix x' = R x + T).
    #[command(
        long_about = "Apply an affine map to the control points (exact for NURBS). Either \
                      --matrix with 12 numbers (rows of [R | T], the IGES 124 layout), or \
                      any of --scale, --rotate and --translate, applied in that order \
                      (scale about the origin, rotation about an axis through the origin \
                      by degrees, right-handed, then translation).",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx transform part.step -o moved.step --translate 10,0,0\n",
            "  nurbsx transform curve.json -o turned.json --rotate 0,0,1,90 --scale 2\n",
            "  nurbsx transform part.igs -o out.igs --matrix 1,0,0,5,0,1,0,0,0,0,1,0\n\n",
            "Exit codes:\n",
            "  0  written\n",
            "  1  the input is invalid or over a limit\n",
            "  2  usage or I/O error"
        )
    )]
    Transform(TransformArgs),
    /// Extract the isoparametric curve u = U or v = V of a surface (exact).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx iso surface.json -o curve.json --u 0.5\n",
        "  nurbsx iso part.step -o edge.step --entity '#17' --v 0\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (a curve given, parameter outside the domain)"
    ))]
    Iso(IsoArgs),
    /// Convert closed curves/surfaces to the periodic form (wrapped poles).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx periodic closed.json -o periodic.json\n",
        "  nurbsx periodic part.igs -o periodic.igs --direction u --tolerance 1e-7\n\n",
        "The seam must be C^(p-1) (homogeneously). `nurbsx clamp` (alias `open`) goes back.\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid, not closed, or not smooth enough at the seam\n",
        "  2  usage or I/O error"
    ))]
    Periodic(PeriodicArgs),
    /// The k-th derivative of a polynomial curve as a B-spline curve (A3.3).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx derivative-curve curve.json -o hodograph.json\n",
        "  nurbsx derivative-curve part.step -o d2.step --order 2 --entity '#17'\n\n",
        "The result has degree p - k, the knots without the first and last k, and the \n",
        "control points of seed 000 eq. 2-103; rational curves are refused.\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit\n",
        "  2  usage or I/O error (order not below the degree, rational curve, surface)"
    ))]
    DerivativeCurve(DerivativeCurveArgs),
    /// Build an exact curve or surface: circle, arc, ellipse, line, cylinder, cone, sphere,
    /// torus, or a revolution, extrusion, ruled surface or Coons patch of curves from files.
    #[command(
        long_about = "Build an exact NURBS curve or surface from its defining numbers (conic \
                      arcs with the fewest segments, NURBS Book A7.1; revolution A8.1; the \
                      ISO 10303-42 quadrics) and write it as STEP, IGES or model JSON. Lengths \
                      are in millimetres, angles in degrees; --axis is the normal of circles \
                      and ellipses and the axis of the surfaces; --reference is the direction \
                      of angle 0 (default: perpendicular to the axis).",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx make circle --radius 2 -o circle.step\n",
            "  nurbsx make arc --centre 1,0,0 --radius 1 --start 0 --end 240 -o arc.json\n",
            "  nurbsx make ellipse --major 3 --minor 1 -o ellipse.igs\n",
            "  nurbsx make line --p0 0,0,0 --p1 1,2,3 -o line.json\n",
            "  nurbsx make cylinder --radius 5 --height 20 --axis 0,0,1 -o cyl.step\n",
            "  nurbsx make cone --radius 5 --semi-angle 30 --height 4 -o cone.step\n",
            "  nurbsx make sphere --radius 3 -o ball.igs\n",
            "  nurbsx make torus --major 5 --minor 1 -o ring.step\n",
            "  nurbsx make revolve profile.json --axis 0,0,1 --angle 180 -o half.step\n",
            "  nurbsx make extrude curve.json --direction 0,0,10 -o wall.step\n",
            "  nurbsx make ruled rail1.json rail2.json -o ruled.step\n",
            "  nurbsx make coons bottom.json top.json left.json right.json -o patch.step\n\n",
            "Exit codes:\n",
            "  0  written\n",
            "  1  an input curve file is invalid or over a limit\n",
            "  2  usage or I/O error (missing or out-of-range numbers)"
        )
    )]
    Make(MakeArgs),
    /// Fit a curve to points or a surface to a grid: interpolation or least squares.
    #[command(
        long_about = "Fit a polynomial B-spline to POINTS. Without --poles the result passes \
                      through every point (curves: NURBS Book A9.1; grids: A9.4); with \
                      --poles N it is the least-squares fit with N poles (section 9.4.1, \
                      knots by eqs. 9.68/9.69; grids: A9.7), the first and last points (a \
                      grid's corners) interpolated. Parameters by --params (uniform, chord \
                      or centripetal; a grid's rows' parameters averaged, A9.3), knots by \
                      averaging for interpolation. The summary gives the residual: the \
                      largest and RMS distance of the points from the result at their \
                      parameters. POINTS is a JSON array of [x, y] or [x, y, z] or text \
                      with one point per line (commas or spaces; `#` comments), at most \
                      2000; a grid is a JSON array of rows of points (row i at the i-th u, \
                      every row as long), at most 2000 per direction and 250000 in all.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx fit points.csv --degree 3 -o curve.step\n",
            "  nurbsx fit points.json --degree 5 --params centripetal -o curve.json\n",
            "  nurbsx fit points.csv --degree 3 --poles 12 -o smooth.json\n",
            "  nurbsx fit grid.json --degree 3 --degree-v 2 -o patch.step\n",
            "  nurbsx fit grid.json --degree 3 --poles 8 --poles-v 6 -o approx.igs\n\n",
            "Exit codes:\n",
            "  0  written\n",
            "  1  over the point limit, coincident points or a singular system\n",
            "  2  usage or I/O error (unreadable points, too few points for the degree, a pole \n",
            "     count outside degree + 1 .. points - 1)"
        )
    )]
    Fit(FitArgs),
    // --- measure and compare ---
    /// Measure curves and surfaces: lengths, areas, closest points.
    #[command(
        long_about = "Measure every curve and surface of IN (or the one --entity names): a \
                      curve's length and a surface's area by adaptive Gauss-Kronrod \
                      quadrature (7/15 points per direction, cut at the knots, the worst \
                      piece halved until the error estimate |K15 - G7| adds up to at most \
                      --tolerance), and with --closest X,Y,Z each one's closest point to X,Y,Z \
                      (NURBS Book section 6.1: a sampling of every knot span starts Newton's \
                      iteration) and the nearest entity.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx measure circle.json\n",
            "  nurbsx measure part.step --tolerance 1e-6 --json\n",
            "  nurbsx measure ball.igs --closest 1,2,3 --entity D1\n\n",
            "Exit codes:\n",
            "  0  measured to the tolerance\n",
            "  1  invalid input, or a length or area whose error estimate stayed above the \n",
            "     tolerance (the piece limit was reached; the value and estimate are reported)\n",
            "  2  usage or I/O error"
        )
    )]
    Measure(MeasureArgs),
    /// The Hausdorff distance between the geometry of two files.
    #[command(
        long_about = "Compare the geometry of A and B: curves with curves, surfaces with \
                      surfaces. Each curve and surface of one file is sampled in every knot \
                      span, and each sample inverted (NURBS Book section 6.1) onto the nearest \
                      entity of the other file, in both directions; the largest distance found \
                      is the Hausdorff distance. It does not depend on how either file \
                      parameterises its geometry. B is read in A's length unit.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx compare part.step part.igs\n",
            "  nurbsx compare a.json b.json --tolerance 1e-9 --json\n\n",
            "Exit codes:\n",
            "  0  compared (within --tolerance when given)\n",
            "  1  the distance is above --tolerance, or an input is invalid, or one file has \n",
            "     curves (surfaces) and the other none\n",
            "  2  usage or I/O error"
        )
    )]
    Compare(CompareArgs),
    // --- end of measure and compare ---
    /// Tessellate curves and surfaces into OBJ, STL, glTF, or an SVG or PNG picture.
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx tessellate part.step -o part.obj --tolerance 0.01\n",
        "  nurbsx tessellate curve.igs -o curve.svg --tolerance 0.001 --entity D1\n\n",
        "Exit codes:\n",
        "  0  written\n",
        "  1  the input is invalid or over a limit (the mesh vertex limit too)\n",
        "  2  usage or I/O error"
    ))]
    Tessellate(TessellateArgs),
    /// Run the HTTP service.
    #[command(
        long_about = "Run the HTTP service (POST /v1/convert, /v1/info, /v1/validate, \
                      /v1/evaluate, ...). Every option can also come from an environment \
                      variable. Stops cleanly on SIGTERM or Ctrl-C.",
        after_help = concat!(
            "Examples:\n",
            "  nurbsx serve --addr 0.0.0.0:8080 --max-body 128MiB --timeout 2m\n",
            "  NURBSX_ADDR=127.0.0.1:9000 NURBSX_CONCURRENCY=4 nurbsx serve\n\n",
            "Exit codes:\n",
            "  0  stopped cleanly\n",
            "  2  usage error, or the address cannot be bound"
        )
    )]
    Serve(ServeArgs),
    /// Show the help of nurbsx, of a command, or of a topic (limits, exit-codes, output).
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx help convert\n",
        "  nurbsx help limits\n",
        "  nurbsx help exit-codes\n\n",
        "Exit codes:\n",
        "  0  shown\n",
        "  2  usage error (unknown command or topic)"
    ))]
    Help(HelpArgs),
    /// Print a shell completion script on stdout.
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx completions bash > ~/.local/share/bash-completion/completions/nurbsx\n",
        "  nurbsx completions zsh > ~/.zfunc/_nurbsx\n",
        "  nurbsx completions fish > ~/.config/fish/completions/nurbsx.fish\n",
        "  nurbsx completions powershell >> $PROFILE\n\n",
        "Exit codes:\n",
        "  0  printed\n",
        "  2  usage error (unknown shell) or I/O error"
    ))]
    Completions(CompletionsArgs),
    /// Print a man page (roff) on stdout, or write one per command with --out-dir.
    #[command(after_help = concat!(
        "Examples:\n",
        "  nurbsx man | man -l -\n",
        "  nurbsx man convert | man -l -\n",
        "  nurbsx man --out-dir target/man\n\n",
        "Exit codes:\n",
        "  0  printed or written\n",
        "  2  usage error (unknown command) or I/O error"
    ))]
    Man(ManArgs),
}

/// `nurbsx help`.
#[derive(Debug, Args)]
pub struct HelpArgs {
    /// A command (`convert`), or a topic: `limits`, `exit-codes`, `output`.
    #[arg(value_name = "COMMAND|TOPIC")]
    pub topic: Option<String>,
}

/// `nurbsx completions`.
#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// `nurbsx man`.
#[derive(Debug, Args)]
pub struct ManArgs {
    /// The command whose page to print (default: the nurbsx page).
    #[arg(value_name = "COMMAND", conflicts_with = "out_dir")]
    pub command: Option<String>,
    /// Write every page (nurbsx.1, nurbsx-convert.1, ...) into this folder instead.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<std::path::PathBuf>,
}

/// An output exchange format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// STEP Part 21 (ISO 10303-21).
    Step,
    /// IGES 5.3.
    Iges,
}

/// An output format for the modify commands (which also write model JSON).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelFormatArg {
    /// STEP Part 21 (ISO 10303-21).
    Step,
    /// IGES 5.3.
    Iges,
    /// nurbsx model JSON.
    Json,
}

/// The STEP application protocol written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SchemaArg {
    /// AUTOMOTIVE_DESIGN (the default, as Open CASCADE).
    Ap214,
    /// CONFIG_CONTROL_DESIGN.
    Ap203,
    /// AP242 managed model-based 3D engineering.
    Ap242,
}

impl From<SchemaArg> for StepSchema {
    fn from(s: SchemaArg) -> Self {
        match s {
            SchemaArg::Ap214 => StepSchema::Ap214,
            SchemaArg::Ap203 => StepSchema::Ap203,
            SchemaArg::Ap242 => StepSchema::Ap242,
        }
    }
}

/// `nurbsx convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input file(s) or folder(s); `-` reads standard input.
    #[arg(required = true, value_name = "IN")]
    pub inputs: Vec<PathBuf>,
    /// Output file for a single input; `-` writes standard output.
    #[arg(short, long, value_name = "OUT", conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Output folder for a batch (many files or folders); the folder layout is kept.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Output format (default: from OUT's extension, else the input's format).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub to: Option<FormatArg>,
    /// STEP schema to write.
    #[arg(long, value_enum, default_value_t = SchemaArg::Ap214)]
    pub schema: SchemaArg,
    /// Length unit to write: keep, mm, cm, m, in, ft (also um, km, mil, uin, mi).
    #[arg(long, value_name = "UNIT", value_parser = parse_units, default_value = "keep")]
    pub units: UnitsArg,
    /// Clamp every knot vector (shape unchanged).
    #[arg(long, conflicts_with = "unclamp")]
    pub clamp: bool,
    /// Unclamp every knot vector (shape unchanged).
    #[arg(long)]
    pub unclamp: bool,
    /// Re-read the output and compare every entity with its input by sampling; fail when the
    /// deviation relative to the entity's size exceeds TOL (default 1e-9). A tolerance is
    /// given with `=` (`--verify=1e-12`), so `--verify in.step` never reads the file as TOL.
    #[arg(long, value_name = "TOL", num_args = 0..=1, require_equals = true,
          default_missing_value = "1e-9", value_parser = parse_tolerance)]
    pub verify: Option<f64>,
    /// Write a JSON report (batch: JSON Lines, one object per file).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Time stamp written in the file header (ISO 8601, default: now), for reproducible output.
    #[arg(long, value_name = "YYYY-MM-DDTHH:MM:SS")]
    pub timestamp: Option<String>,
    /// IGES: trim to the declared parameter range (exact, by knot insertion).
    #[arg(long)]
    pub trim_to_range: bool,
    /// Curves and surfaces only: faces, edges, shells, solids, placements left out (warned).
    #[arg(long)]
    pub geometry_only: bool,
    /// IGES input: join curve ends into loops and sew 144 faces into shells and solids within
    /// TOL (default: the larger of the file's resolution and 1e-7 of the model's size).
    #[arg(long, value_name = "TOL", value_parser = parse_tolerance)]
    pub sew_tolerance: Option<f64>,
    /// IGES output: solids and shells as 186 B-rep objects (502-514), not 144 trimmed surfaces.
    #[arg(long)]
    pub iges_brep: bool,
    /// STEP output: an assembly as placed copies in one product, not its product structure.
    #[arg(long)]
    pub flatten_assemblies: bool,
    /// Violations of the standard are errors (exit 1) as in `validate`; output still written.
    #[arg(long)]
    pub strict: bool,
    /// Batch: number of files converted at once, 1 to 256 (default: the number of cores).
    #[arg(short = 'j', long, value_name = "N",
          value_parser = clap::value_parser!(u16).range(1..=256))]
    pub jobs: Option<u16>,
    /// Batch: what to do when two inputs would be written to the same output (`a.igs` and
    /// `a.step` both to `a.step`): error (the default: nothing is converted), rename
    /// (`a-2.step`, with a warning), overwrite (the later input wins, with a warning).
    #[arg(long, value_enum, value_name = "POLICY", default_value_t = CollisionArg::Error)]
    pub on_collision: CollisionArg,
}

/// `--on-collision`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CollisionArg {
    /// Refuse the batch (exit 2) and name the colliding inputs.
    Error,
    /// Number the later outputs: `a-2.step`, `a-3.step`, ...
    Rename,
    /// Convert only the last input of each colliding group; the others are not written.
    Overwrite,
}

/// `--units`: keep the document's unit or convert to one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitsArg(pub Option<LengthUnit>);

/// `nurbsx info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input file (STEP, IGES or model JSON); `-` reads standard input.
    #[arg(value_name = "FILE")]
    pub input: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Every violation of the standard is an error (exit 1) as in `validate`, not only a
    /// warning.
    #[arg(long)]
    pub strict: bool,
    /// Show the reading `convert --geometry-only` makes: every curve and surface of the file
    /// as loose geometry (faces, edges, shells, solids, placements left out, warned).
    #[arg(long)]
    pub geometry_only: bool,
}

/// Output formats of `validate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ValidateFormat {
    /// `file:line:col: error[code]: message` lines and a summary per file.
    Text,
    /// One JSON array of reports.
    Json,
    /// JUnit XML: one testcase per file.
    Junit,
    /// SARIF 2.1.0 for code-scanning tools.
    Sarif,
}

/// `nurbsx validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Files to check; folders are searched recursively for .step/.stp/.p21/.igs/.iges.
    #[arg(required = true, value_name = "FILE")]
    pub inputs: Vec<PathBuf>,
    /// Same as --format json.
    #[arg(long, conflicts_with = "format")]
    pub json: bool,
    /// Warnings make a file invalid too.
    #[arg(long)]
    pub strict: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = ValidateFormat::Text)]
    pub format: ValidateFormat,
}

/// `nurbsx evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Input file (STEP, IGES or model JSON); `-` reads standard input.
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Entity id: `#17` (STEP), `D5` (IGES), or the index for model JSON (default: the first).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
    /// A parameter: `U` for curves, `U,V` for surfaces. Repeatable.
    #[arg(long = "at", value_name = "U[,V]", value_parser = parse_tuple, allow_hyphen_values = true)]
    pub at: Vec<Vec<f64>>,
    /// A file of parameters: one tuple per line (`u`, `u,v` or `u v`; `#` comments), or a
    /// JSON array of arrays.
    #[arg(long, value_name = "FILE")]
    pub params: Option<PathBuf>,
    /// Also compute derivatives up to order K.
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub derivatives: usize,
    /// Also compute unit normals (surfaces).
    #[arg(long)]
    pub normals: bool,
    /// Also compute curvature.
    #[arg(long)]
    pub curvature: bool,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Where a modify command writes and in what format.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Output file; `-` writes standard output.
    #[arg(short, long, value_name = "OUT", required = true)]
    pub output: PathBuf,
    /// Output format (default: from OUT's extension, else the input's format).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub to: Option<ModelFormatArg>,
    /// Model JSON output: write each curve's knots in knot-interval form (seed 003:
    /// `knot_intervals`, `knot_origin`, `outer_knot_intervals`) instead of `knots`;
    /// surfaces keep knot vectors. Refused for STEP and IGES output.
    #[arg(long)]
    pub knot_intervals: bool,
}

/// A surface direction on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DirectionArg {
    /// Along u.
    U,
    /// Along v.
    V,
    /// Both directions.
    Both,
}

impl From<DirectionArg> for Direction {
    fn from(d: DirectionArg) -> Self {
        match d {
            DirectionArg::U => Direction::U,
            DirectionArg::V => Direction::V,
            DirectionArg::Both => Direction::Both,
        }
    }
}

/// The surface direction of a knot insertion (one at a time).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum KnotDirectionArg {
    /// Along u.
    U,
    /// Along v.
    V,
}

impl From<KnotDirectionArg> for Direction {
    fn from(d: KnotDirectionArg) -> Self {
        match d {
            KnotDirectionArg::U => Direction::U,
            KnotDirectionArg::V => Direction::V,
        }
    }
}

/// `nurbsx elevate`.
#[derive(Debug, Args)]
pub struct ElevateArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Raise the degree by N.
    #[arg(long, value_name = "N")]
    pub by: usize,
    /// Surface direction(s).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx clamp` and `nurbsx unclamp`.
#[derive(Debug, Args)]
pub struct SimpleOpArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Surface direction(s).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx insert-knot`.
#[derive(Debug, Args)]
pub struct InsertKnotArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// The parameter value of the new knot.
    #[arg(long, value_name = "U", value_parser = parse_finite, allow_negative_numbers = true)]
    pub at: f64,
    /// How many times to insert it.
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub times: usize,
    /// Surface direction (u or v); curves ignore it.
    #[arg(long, value_enum, default_value_t = KnotDirectionArg::U)]
    pub direction: KnotDirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx refine`.
#[derive(Debug, Args)]
pub struct RefineArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// The knots to insert, comma-separated (a value given twice is inserted twice).
    #[arg(long, value_name = "U,...", value_parser = parse_numbers, allow_hyphen_values = true,
          required_unless_present = "halve", conflicts_with = "halve")]
    pub knots: Option<NumberList>,
    /// Interval halving (seed 003): insert the midpoint of every non-degenerate knot span
    /// of the domain instead of --knots.
    #[arg(long)]
    pub halve: bool,
    /// Surface direction (u or v; `both` with --halve); curves ignore it.
    #[arg(long, value_enum, default_value_t = DirectionArg::U)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx reduce`.
#[derive(Debug, Args)]
pub struct ReduceArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Largest accepted deviation (model units).
    #[arg(long, value_name = "T", value_parser = parse_tolerance)]
    pub tolerance: f64,
    /// Surface direction(s).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx remove-knots`.
#[derive(Debug, Args)]
pub struct ToleranceOpArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Largest accepted change of the shape (model units).
    #[arg(long, value_name = "T", value_parser = parse_tolerance)]
    pub tolerance: f64,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx decompose`.
#[derive(Debug, Args)]
pub struct EntityOpArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx split`.
#[derive(Debug, Args)]
pub struct SplitArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// The parameter, strictly inside the domain.
    #[arg(long, value_name = "T", value_parser = parse_finite, allow_negative_numbers = true)]
    pub at: f64,
    /// Surface direction (u or v); curves ignore it.
    #[arg(long, value_enum, default_value_t = KnotDirectionArg::U)]
    pub direction: KnotDirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx join`.
#[derive(Debug, Args)]
pub struct JoinArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Largest accepted gap between a curve's end and the next curve's start.
    #[arg(long, value_name = "T", value_parser = parse_tolerance, default_value_t = 1e-9)]
    pub tolerance: f64,
}

/// `nurbsx reparameterize` (`--to` is the domain here, so the output format comes from
/// OUT's extension, else the input's).
#[derive(Debug, Args)]
pub struct ReparameterizeArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output file (format from its extension, else the input's); `-` writes standard output.
    #[arg(short, long, value_name = "OUT", required = true)]
    pub output: PathBuf,
    /// The new domain `A,B` (A < B).
    #[arg(long, value_name = "A,B", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub to: NumberList,
    /// Model JSON output: curves' knots in knot-interval form (as for the other commands).
    #[arg(long)]
    pub knot_intervals: bool,
    /// Surface direction(s).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx transform`.
#[derive(Debug, Args)]
pub struct TransformArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// 12 numbers: the rows of [R | T] (x' = R x + T).
    #[arg(long, value_name = "R11,R12,R13,T1,...", value_parser = parse_numbers,
          allow_hyphen_values = true, conflicts_with_all = ["translate", "rotate", "scale"])]
    pub matrix: Option<NumberList>,
    /// Translation `X,Y,Z` (applied last).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub translate: Option<NumberList>,
    /// Rotation `AX,AY,AZ,DEGREES` about an axis through the origin (right-handed).
    #[arg(long, value_name = "AX,AY,AZ,DEG", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub rotate: Option<NumberList>,
    /// Uniform scale about the origin (applied first).
    #[arg(long, value_name = "S", value_parser = parse_finite, allow_negative_numbers = true)]
    pub scale: Option<f64>,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx iso`.
#[derive(Debug, Args)]
pub struct IsoArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// The curve at u = U (running along v).
    #[arg(long, value_name = "U", value_parser = parse_finite, allow_negative_numbers = true,
          required_unless_present = "v", conflicts_with = "v")]
    pub u: Option<f64>,
    /// The curve at v = V (running along u).
    #[arg(long, value_name = "V", value_parser = parse_finite, allow_negative_numbers = true)]
    pub v: Option<f64>,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx periodic`.
#[derive(Debug, Args)]
pub struct PeriodicArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Largest accepted difference of the wrapped poles (model units).
    #[arg(long, value_name = "T", value_parser = parse_tolerance, default_value_t = 1e-9)]
    pub tolerance: f64,
    /// Surface direction(s).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx derivative-curve`.
#[derive(Debug, Args)]
pub struct DerivativeCurveArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Derivative order k (1 <= k < degree).
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub order: usize,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// What `nurbsx make` builds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MakeKind {
    /// A full circle (--centre, --axis, --radius).
    Circle,
    /// A circular arc (--centre, --axis, --radius, --start, --end).
    Arc,
    /// An ellipse or elliptic arc (--centre, --axis, --reference, --major, --minor, --start, --end).
    Ellipse,
    /// A line segment (--p0, --p1).
    Line,
    /// A cylinder (--centre of the base, --axis, --radius, --height, --sweep).
    Cylinder,
    /// A cone (--centre of the base, --axis, --radius, --semi-angle, --height, --sweep).
    Cone,
    /// A sphere (--centre, --axis, --radius).
    Sphere,
    /// A torus (--centre, --axis, --major, --minor).
    Torus,
    /// The first curve of CURVE revolved (--axis-point, --axis, --angle).
    Revolve,
    /// The first curve of CURVE swept along --direction.
    Extrude,
    /// The ruled surface between the first curves of two files.
    Ruled,
    /// The bilinearly blended Coons patch of four boundary curves (files): S(u,0), S(u,1),
    /// S(0,v), S(1,v); polynomial curves whose corners meet within --tolerance.
    Coons,
}

/// `nurbsx make`.
#[derive(Debug, Args)]
pub struct MakeArgs {
    /// What to build.
    #[arg(value_enum, value_name = "SHAPE")]
    pub shape: MakeKind,
    /// Curve file(s) for revolve, extrude (one), ruled (two) and coons (four: S(u,0), S(u,1),
    /// S(0,v), S(1,v)): STEP, IGES or model JSON.
    #[arg(value_name = "CURVE")]
    pub curves: Vec<PathBuf>,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Centre (circles, ellipses, sphere, torus) or base centre (cylinder, cone).
    #[arg(long, visible_alias = "center", value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub centre: Option<NumberList>,
    /// Normal of circles and ellipses, axis of the surfaces (default 0,0,1).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub axis: Option<NumberList>,
    /// Direction of angle 0 (default: perpendicular to the axis).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub reference: Option<NumberList>,
    /// Radius.
    #[arg(long, value_name = "R", value_parser = parse_finite)]
    pub radius: Option<f64>,
    /// Start angle of arcs (degrees, default 0).
    #[arg(long, value_name = "DEG", value_parser = parse_finite, allow_negative_numbers = true, default_value_t = 0.0)]
    pub start: f64,
    /// End angle of arcs (degrees, default 360).
    #[arg(long, value_name = "DEG", value_parser = parse_finite, allow_negative_numbers = true, default_value_t = 360.0)]
    pub end: f64,
    /// Major semi-axis (ellipse) or major radius (torus).
    #[arg(long, value_name = "A", value_parser = parse_finite)]
    pub major: Option<f64>,
    /// Minor semi-axis (ellipse) or tube radius (torus).
    #[arg(long, value_name = "B", value_parser = parse_finite)]
    pub minor: Option<f64>,
    /// Start point of a line.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub p0: Option<NumberList>,
    /// End point of a line.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub p1: Option<NumberList>,
    /// Height along the axis (cylinder, cone).
    #[arg(long, value_name = "H", value_parser = parse_finite)]
    pub height: Option<f64>,
    /// Semi-angle of a cone (degrees).
    #[arg(long, value_name = "DEG", value_parser = parse_finite, allow_negative_numbers = true)]
    pub semi_angle: Option<f64>,
    /// Sweep of a cylinder or cone (degrees, default 360).
    #[arg(long, value_name = "DEG", value_parser = parse_finite, default_value_t = 360.0)]
    pub sweep: f64,
    /// A point of the revolution axis (default the origin).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub axis_point: Option<NumberList>,
    /// Revolution angle (degrees, default 360).
    #[arg(long, value_name = "DEG", value_parser = parse_finite, default_value_t = 360.0)]
    pub angle: f64,
    /// Extrusion vector.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub direction: Option<NumberList>,
    /// Largest accepted gap between the corners of Coons boundaries.
    #[arg(long, value_name = "T", value_parser = parse_tolerance, default_value_t = 1e-9)]
    pub tolerance: f64,
}

/// The parameter method of `nurbsx fit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ParamsArg {
    /// Equally spaced.
    Uniform,
    /// Proportional to the chord lengths.
    Chord,
    /// Proportional to the square roots of the chord lengths.
    Centripetal,
}

/// `nurbsx fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// The points (JSON array or text, one point per line) or a grid (JSON array of rows).
    #[arg(value_name = "POINTS")]
    pub input: PathBuf,
    /// Output.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Degree of the curve (of a surface along u).
    #[arg(long, value_name = "P", default_value_t = 3)]
    pub degree: usize,
    /// Degree of a surface along v (default: --degree).
    #[arg(long, value_name = "Q")]
    pub degree_v: Option<usize>,
    /// Least squares with this many poles (of a surface along u); without it the fit
    /// interpolates.
    #[arg(long, value_name = "N")]
    pub poles: Option<usize>,
    /// Poles of a least-squares surface along v (default: --poles).
    #[arg(long, value_name = "M", requires = "poles")]
    pub poles_v: Option<usize>,
    /// How the points get their parameters.
    #[arg(long, value_enum, default_value_t = ParamsArg::Chord)]
    pub params: ParamsArg,
}

// --- measure and compare ---

/// `nurbsx measure`.
#[derive(Debug, Args)]
pub struct MeasureArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Only this entity (default: every curve and surface).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
    /// Also find each entity's point closest to X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_numbers, allow_hyphen_values = true)]
    pub closest: Option<NumberList>,
    /// Largest error estimate of a length (model units) or an area (model units squared).
    #[arg(long, value_name = "T", value_parser = parse_tolerance, default_value_t = 1e-9)]
    pub tolerance: f64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// `nurbsx compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The first file (STEP, IGES or model JSON).
    #[arg(value_name = "A")]
    pub first: PathBuf,
    /// The second file, read in the first one's length unit.
    #[arg(value_name = "B")]
    pub second: PathBuf,
    /// Exit 1 when the distance is above T (model units of A).
    #[arg(long, value_name = "T", value_parser = parse_tolerance)]
    pub tolerance: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

// --- end of measure and compare ---

/// A tessellation output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MeshFormatArg {
    /// Wavefront OBJ: welded triangle meshes and polylines.
    Obj,
    /// Binary STL: triangles only.
    Stl,
    /// Binary glTF 2.0 (.glb): triangle meshes and line strips.
    Glb,
    /// SVG picture: shaded isometric (or, for plane curves, top) view with frame, scale bar
    /// and labels.
    Svg,
    /// The SVG picture as PNG (rendered by resvg).
    Png,
}

/// `nurbsx tessellate`.
#[derive(Debug, Args)]
pub struct TessellateArgs {
    /// Input file (STEP, IGES or model JSON).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output file (.obj, .stl, .glb, .svg or .png); `-` writes standard output (then give
    /// --format).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Mesh format (default: from OUT's extension).
    #[arg(long, value_enum)]
    pub format: Option<MeshFormatArg>,
    /// Largest distance between the mesh and the exact geometry (chord tolerance), in the
    /// file's unit.
    #[arg(long, value_name = "T", value_parser = parse_tolerance)]
    pub tolerance: f64,
    /// Only this entity (default: all).
    #[arg(long, value_name = "ID")]
    pub entity: Option<String>,
}

/// `nurbsx serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "NURBSX_ADDR", default_value = "127.0.0.1:8080")]
    pub addr: SocketAddr,
    /// Largest request body, e.g. 64MiB.
    #[arg(long, env = "NURBSX_MAX_BODY", value_name = "SIZE", default_value = "64MiB",
          value_parser = parse_bytes)]
    pub max_body: usize,
    /// Per-request time limit, e.g. 60s, 500ms, 2m.
    #[arg(long, env = "NURBSX_TIMEOUT", value_name = "DURATION", default_value = "60s",
          value_parser = parse_duration)]
    pub timeout: Duration,
    /// Most requests doing CPU work at once (default: the number of cores).
    #[arg(long, env = "NURBSX_CONCURRENCY", value_name = "N",
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub concurrency: Option<u32>,
    /// Largest reply one request may build (evaluation results, mesh, written file),
    /// estimated before the work; over it the reply is 413.
    #[arg(long, env = "NURBSX_MAX_REPLY_BYTES", value_name = "SIZE", default_value = "64MiB",
          value_parser = parse_bytes)]
    pub max_reply_bytes: usize,
    /// Most request bodies being received at once (they take no computing place until
    /// complete).
    #[arg(long, env = "NURBSX_MAX_UPLOADS", value_name = "N", default_value = "256",
          value_parser = clap::value_parser!(u32).range(1..))]
    pub max_uploads: u32,
    /// Most bytes the bodies being received may hold together.
    #[arg(long, env = "NURBSX_MAX_UPLOAD_BYTES", value_name = "SIZE", default_value = "256MiB",
          value_parser = parse_bytes)]
    pub max_upload_bytes: usize,
    /// Slowest average upload accepted after a 5 s grace, per second (slower: 408).
    #[arg(long, env = "NURBSX_MIN_UPLOAD_RATE", value_name = "SIZE", default_value = "16KiB",
          value_parser = parse_bytes)]
    pub min_upload_rate: usize,
    /// Time a connection has to send a complete request head, from opening or from the first
    /// byte of a later request.
    #[arg(long, env = "NURBSX_HEADER_TIMEOUT", value_name = "DURATION", default_value = "10s",
          value_parser = parse_duration)]
    pub header_timeout: Duration,
    /// How long a keep-alive connection (HTTP/1.1 or HTTP/2) may stay idle between requests
    /// before the server closes it.
    #[arg(long, env = "NURBSX_IDLE_TIMEOUT", value_name = "DURATION", default_value = "60s",
          value_parser = parse_duration)]
    pub idle_timeout: Duration,
    /// How long a streamed reply waits for a client to take its next chunk before the work
    /// stops and the connection is closed.
    #[arg(long, env = "NURBSX_WRITE_TIMEOUT", value_name = "DURATION", default_value = "30s",
          value_parser = parse_duration)]
    pub write_timeout: Duration,
    /// After SIGTERM: how long to keep serving with /readyz at 503 before closing.
    #[arg(long, env = "NURBSX_DRAIN", value_name = "DURATION", default_value = "5s",
          value_parser = parse_duration)]
    pub drain: Duration,
}

/// Parses `keep` or a length-unit name.
pub fn parse_units(s: &str) -> Result<UnitsArg, String> {
    if s.eq_ignore_ascii_case("keep") {
        return Ok(UnitsArg(None));
    }
    LengthUnit::parse_name(s)
        .map(|u| UnitsArg(Some(u)))
        .ok_or_else(|| {
            format!("unknown unit `{s}` (expected keep, mm, cm, m, in, ft, um, km, mil, uin, mi)")
        })
}

/// Parses a finite number.
pub fn parse_finite(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("`{}` is not a finite number", clip(s))),
        Err(_) => Err(format!("`{}` is not a number", clip(s))),
    }
}

/// Parses a positive finite tolerance.
pub fn parse_tolerance(s: &str) -> Result<f64, String> {
    let x = parse_finite(s)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(format!("the tolerance must be positive, got {s}"))
    }
}

/// Parses a parameter tuple `u` or `u,v` (commas and/or whitespace separate). Stops at the
/// third number, so a huge line costs no memory.
pub fn parse_tuple(s: &str) -> Result<Vec<f64>, String> {
    let mut values = Vec::with_capacity(2);
    for token in s
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
    {
        if values.len() == 2 {
            return Err(format!(
                "expected `u` or `u,v`, got more than 2 numbers in `{}`",
                clip(s)
            ));
        }
        values.push(parse_finite(token)?);
    }
    if values.is_empty() {
        return Err("empty parameter tuple".to_owned());
    }
    Ok(values)
}

/// A comma-separated list of numbers on the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct NumberList(pub Vec<f64>);

/// Parses comma- (or space-) separated finite numbers (at most 4096).
pub fn parse_numbers(s: &str) -> Result<NumberList, String> {
    let tokens: Vec<&str> = s
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .take(4097)
        .collect();
    if tokens.len() > 4096 {
        return Err("more than 4096 numbers".to_owned());
    }
    if tokens.is_empty() {
        return Err("empty list of numbers".to_owned());
    }
    tokens
        .into_iter()
        .map(parse_finite)
        .collect::<Result<_, _>>()
        .map(NumberList)
}

/// The first 40 characters of a value for a message.
fn clip(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_owned(),
    }
}

/// Parses a byte size: `1024`, `64k`, `64KiB`, `10MB`, `2GiB` (binary multiples for
/// k/K/KiB/M/MiB/G/GiB; decimal for KB/MB/GB).
pub fn parse_bytes(s: &str) -> Result<usize, String> {
    let t = s.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (digits, suffix) = t.split_at(split);
    let n: u64 = digits
        .parse()
        .map_err(|_| format!("`{s}` is not a size (e.g. 1048576, 512KiB, 64MiB, 2GiB)"))?;
    let factor: u64 = match suffix.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kib" => 1 << 10,
        "kb" => 1_000,
        "m" | "mib" => 1 << 20,
        "mb" => 1_000_000,
        "g" | "gib" => 1 << 30,
        "gb" => 1_000_000_000,
        other => return Err(format!("unknown size suffix `{other}` in `{s}`")),
    };
    n.checked_mul(factor)
        .and_then(|b| usize::try_from(b).ok())
        .ok_or_else(|| format!("`{s}` is too large"))
}

/// Parses a duration: `60`, `60s`, `500ms`, `2m`, `1h`.
pub fn parse_duration(s: &str) -> Result<Duration, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, suffix) = t.split_at(split);
    let n: f64 = number
        .parse()
        .map_err(|_| format!("`{s}` is not a duration (e.g. 60s, 500ms, 2m)"))?;
    let seconds = match suffix.trim() {
        "" | "s" => n,
        "ms" => n / 1000.0,
        "m" | "min" => n * 60.0,
        "h" => n * 3600.0,
        other => return Err(format!("unknown duration unit `{other}` in `{s}`")),
    };
    Duration::try_from_secs_f64(seconds).map_err(|_| format!("`{s}` is not a valid duration"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_durations_parse() {
        assert_eq!(parse_bytes("64MiB"), Ok(64 << 20));
        assert_eq!(parse_bytes("10MB"), Ok(10_000_000));
        assert_eq!(parse_bytes("1024"), Ok(1024));
        assert!(parse_bytes("12XB").is_err());
        assert!(parse_bytes("99999999999999999999G").is_err());
        assert_eq!(parse_duration("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse_duration("2m"), Ok(Duration::from_secs(120)));
        assert!(parse_duration("-1s").is_err());
    }

    #[test]
    fn tuples_parse_with_commas_or_spaces() {
        assert_eq!(parse_tuple("0.5"), Ok(vec![0.5]));
        assert_eq!(parse_tuple("0.5, 0.25"), Ok(vec![0.5, 0.25]));
        assert_eq!(parse_tuple("0.5 0.25"), Ok(vec![0.5, 0.25]));
        assert!(parse_tuple("1,2,3").is_err());
        assert!(parse_tuple("nan").is_err());
        assert!(parse_tuple("").is_err());
    }

    #[test]
    fn clap_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
