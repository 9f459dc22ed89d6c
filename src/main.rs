//! The `nurbsx` command-line tool: see `nurbsx --help`.

fn main() -> std::process::ExitCode {
    nurbsx::cli::main()
}
